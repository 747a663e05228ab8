#include "ademono/slam/matcher.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <future>
#include <opencv2/features2d.hpp>

#include "ademono/core/geometry.h"
#include "ademono/core/worker_pool.h"
#include "ademono/feature/line_search_grid.h"
#include "ademono/feature/orb_extractor.h"

namespace ademono {
namespace {

// Fewer keypoints than this are scanned on one thread: handing half to a helper costs a wake-up
// (tens of microseconds), a scan of a few hundred keypoints about a tenth of a millisecond.
constexpr size_t kMinKeypointsToSplit = 200;

// The keypoint within `r` px of the prediction, on its level or the one below, whose descriptor is
// nearest to `descriptor` (candidates for which `skip` is true left out), if it is within
// kOrbDistanceHigh and, when the runner-up is on the same level, clearly better than it (ratio
// `nn_ratio`); -1 otherwise.
template <typename Skip>
int BestInArea(const FrameFeatures& f, const cv::Mat& descriptor,
               const ProjectionPrediction& prediction, float r, float nn_ratio, Skip skip) {
  const int level = prediction.level;
  int best_dist = 256, best_level = -1, best_dist2 = 256, best_level2 = -1;
  int best_idx = -1;
  // Called for every projected map point: the candidates' buffer is reused.
  thread_local std::vector<size_t> candidates;
  f.FeaturesInArea(prediction.u, prediction.v, r, level - 1, level, &candidates);
  for (size_t idx : candidates) {
    if (skip(idx)) continue;
    const int d = DescriptorDistance(descriptor, f.descriptors.row(static_cast<int>(idx)));
    if (d < best_dist) {
      best_dist2 = best_dist;
      best_level2 = best_level;
      best_dist = d;
      best_level = f.keypoints_un[idx].octave;
      best_idx = static_cast<int>(idx);
    } else if (d < best_dist2) {
      best_dist2 = d;
      best_level2 = f.keypoints_un[idx].octave;
    }
  }
  if (best_dist > kOrbDistanceHigh) return -1;
  if (best_level == best_level2 && best_dist > nn_ratio * best_dist2) return -1;
  return best_idx;
}

}  // namespace

int Matcher::SearchByProjection(Frame& current, const Frame& last, float radius) const {
  const FrameFeatures& cf = current.F();
  const FrameFeatures& lf = last.F();
  const Rigid3d& cam_from_world = *current.cam_from_world;
  // Moving forward, points grow in the image (appear on finer levels); backward, coarser.
  const Eigen::Vector3d last_from_current_t =
      (*last.cam_from_world * cam_from_world.inverse()).translation();
  const double baseline = cf.intrinsics.bf / cf.intrinsics.fx;
  const bool forward = last_from_current_t.z() > baseline;
  const bool backward = -last_from_current_t.z() > baseline;

  RotationHistogram rotations;
  int matches = 0;
  std::vector<size_t> candidates;
  for (size_t i = 0; i < last.map_points.size(); ++i) {
    const auto& point = last.map_points[i];
    if (!point || last.outlier[i] || point->bad) continue;
    const Eigen::Vector3d pc = cam_from_world * point->position;
    if (pc.z() <= 0) continue;
    const double inv_z = 1.0 / pc.z();
    const float u = static_cast<float>(cf.intrinsics.fx * pc.x() * inv_z + cf.intrinsics.cx);
    const float v = static_cast<float>(cf.intrinsics.fy * pc.y() * inv_z + cf.intrinsics.cy);
    if (!cf.InBounds(u, v)) continue;
    const int last_octave = lf.keypoints_un[i].octave;
    const float r = radius * cf.pyramid->scale_factors[last_octave];
    if (forward) {
      cf.FeaturesInArea(u, v, r, last_octave, -1, &candidates);
    } else if (backward) {
      cf.FeaturesInArea(u, v, r, 0, last_octave, &candidates);
    } else {
      cf.FeaturesInArea(u, v, r, last_octave - 1, last_octave + 1, &candidates);
    }
    const float ur = static_cast<float>(u - cf.intrinsics.bf * inv_z);
    int best_dist = 256;
    size_t best_idx = 0;
    for (size_t idx : candidates) {
      if (current.map_points[idx] && current.map_points[idx]->NumObservations() > 0) continue;
      if (cf.u_right[idx] > 0 && std::abs(ur - cf.u_right[idx]) > r) continue;
      const int d =
          DescriptorDistance(point->descriptor, cf.descriptors.row(static_cast<int>(idx)));
      if (d < best_dist) {
        best_dist = d;
        best_idx = idx;
      }
    }
    if (best_dist <= kOrbDistanceHigh) {
      current.map_points[best_idx] = point;
      ++matches;
      if (check_orientation_) {
        rotations.Add(lf.keypoints[i].angle, cf.keypoints[best_idx].angle,
                      static_cast<int>(best_idx));
      }
    }
  }
  if (check_orientation_) {
    for (const int idx : rotations.InconsistentMatches()) {
      current.map_points[static_cast<size_t>(idx)].reset();
      --matches;
    }
  }
  return matches;
}

int Matcher::SearchByProjection(Frame& frame, const std::vector<std::shared_ptr<MapPoint>>& points,
                                const std::vector<ProjectionPrediction>& predictions,
                                float radius) const {
  const FrameFeatures& f = frame.F();
  int matches = 0;
  for (size_t k = 0; k < points.size(); ++k) {
    const auto& point = points[k];
    if (point->bad) continue;
    const ProjectionPrediction& pred = predictions[k];
    const int level = pred.level;
    const float r = radius * RadiusByViewingCos(pred.view_cos) * f.pyramid->scale_factors[level];
    const int best = BestInArea(f, point->descriptor, pred, r, nn_ratio_, [&](size_t idx) {
      return (frame.map_points[idx] && frame.map_points[idx]->NumObservations() > 0) ||
             (f.u_right[idx] > 0 &&
              std::abs(pred.u_right - f.u_right[idx]) > r * f.pyramid->scale_factors[level]);
    });
    if (best < 0) continue;
    frame.map_points[static_cast<size_t>(best)] = point;
    ++matches;
  }
  return matches;
}

int Matcher::FindByProjection(const Frame& frame, const MapPoint& point,
                              const ProjectionPrediction& prediction, float radius) const {
  const FrameFeatures& f = frame.F();
  return BestInArea(f, point.descriptor, prediction,
                    radius * f.pyramid->scale_factors[prediction.level], nn_ratio_,
                    [](size_t) { return false; });
}

int Matcher::SearchByProjection(Frame& frame, const KeyFrame& keyframe, float radius,
                                int max_distance) const {
  const FrameFeatures& f = frame.F();
  const Rigid3d& cam_from_world = *frame.cam_from_world;
  const Eigen::Vector3d center = frame.CameraCenter();
  RotationHistogram rotations;
  int matches = 0;
  for (size_t i = 0; i < keyframe.map_points.size(); ++i) {
    const auto& point = keyframe.map_points[i];
    if (!point || point->bad) continue;
    if (std::find(frame.map_points.begin(), frame.map_points.end(), point) !=
        frame.map_points.end())
      continue;
    const Eigen::Vector3d pc = cam_from_world * point->position;
    if (pc.z() <= 0) continue;
    const float u = static_cast<float>(f.intrinsics.fx * pc.x() / pc.z() + f.intrinsics.cx);
    const float v = static_cast<float>(f.intrinsics.fy * pc.y() / pc.z() + f.intrinsics.cy);
    if (!f.InBounds(u, v)) continue;
    const float dist = static_cast<float>((point->position - center).norm());
    if (dist < 0.8f * point->min_distance || dist > 1.2f * point->max_distance) continue;
    const int level = point->PredictScale(dist, f.pyramid->log_scale_factor, f.pyramid->num_levels);
    const float r = radius * f.pyramid->scale_factors[level];
    int best_dist = 256;
    size_t best_idx = 0;
    for (size_t idx : f.FeaturesInArea(u, v, r, level - 1, level + 1)) {
      if (frame.map_points[idx]) continue;
      const int d = DescriptorDistance(point->descriptor, f.descriptors.row(static_cast<int>(idx)));
      if (d < best_dist) {
        best_dist = d;
        best_idx = idx;
      }
    }
    if (best_dist <= max_distance) {
      frame.map_points[best_idx] = point;
      ++matches;
      if (check_orientation_) {
        rotations.Add(keyframe.F().keypoints[i].angle, f.keypoints[best_idx].angle,
                      static_cast<int>(best_idx));
      }
    }
  }
  if (check_orientation_) {
    for (const int idx : rotations.InconsistentMatches()) {
      frame.map_points[static_cast<size_t>(idx)].reset();
      --matches;
    }
  }
  return matches;
}

int Matcher::SearchByDescriptor(const KeyFrame& keyframe, const Frame& frame,
                                std::vector<std::shared_ptr<MapPoint>>& matches) const {
  const FrameFeatures& kf = keyframe.F();
  const FrameFeatures& f = frame.F();
  matches.assign(f.Size(), nullptr);
  std::vector<size_t> kf_indices;
  for (size_t i = 0; i < keyframe.map_points.size(); ++i) {
    if (keyframe.map_points[i] && !keyframe.map_points[i]->bad) kf_indices.push_back(i);
  }
  if (kf_indices.empty() || f.Size() == 0) return 0;

  cv::Mat kf_descriptors(static_cast<int>(kf_indices.size()), 32, CV_8UC1);
  for (size_t k = 0; k < kf_indices.size(); ++k) {
    kf.descriptors.row(static_cast<int>(kf_indices[k]))
        .copyTo(kf_descriptors.row(static_cast<int>(k)));
  }
  // For every frame keypoint its two nearest keyframe keypoints (OpenCV's brute force).
  cv::BFMatcher bf(cv::NORM_HAMMING);
  std::vector<std::vector<cv::DMatch>> knn;
  bf.knnMatch(f.descriptors, kf_descriptors, knn, 2);
  std::vector<int> best_for_kf(kf_indices.size(), 256);
  std::vector<int> best_frame_for_kf(kf_indices.size(), -1);
  for (const auto& m : knn) {
    if (m.empty()) continue;
    const int best = static_cast<int>(m[0].distance);
    const int second = m.size() > 1 ? static_cast<int>(m[1].distance) : 256;
    if (best > kOrbDistanceLow || best >= nn_ratio_ * second) continue;
    const size_t best_k = static_cast<size_t>(m[0].trainIdx);
    // Keep one frame keypoint per keyframe keypoint: the closest (lowest index on ties).
    if (best < best_for_kf[best_k]) {
      best_for_kf[best_k] = best;
      best_frame_for_kf[best_k] = m[0].queryIdx;
    }
  }
  RotationHistogram rotations;
  int n = 0;
  for (size_t k = 0; k < kf_indices.size(); ++k) {
    if (best_frame_for_kf[k] < 0) continue;
    const size_t j = static_cast<size_t>(best_frame_for_kf[k]);
    matches[j] = keyframe.map_points[kf_indices[k]];
    ++n;
    rotations.Add(kf.keypoints[kf_indices[k]].angle, f.keypoints[j].angle, static_cast<int>(j));
  }
  if (check_orientation_) {
    for (const int j : rotations.InconsistentMatches()) {
      matches[static_cast<size_t>(j)].reset();
      --n;
    }
  }
  return n;
}

int Matcher::Fuse(Map& map, KeyFrame& keyframe,
                  const std::vector<std::shared_ptr<MapPoint>>& points, float radius) const {
  const FrameFeatures& f = keyframe.F();
  const Rigid3d& cam_from_world = keyframe.cam_from_world;
  const Eigen::Vector3d center = keyframe.CameraCenter();
  int fused = 0;
  std::vector<size_t> candidates;
  for (const auto& point : points) {
    if (!point || point->bad || point->IsInKeyFrame(&keyframe)) continue;
    const Eigen::Vector3d pc = cam_from_world * point->position;
    if (pc.z() <= 0) continue;
    const double inv_z = 1.0 / pc.z();
    const float u = static_cast<float>(f.intrinsics.fx * pc.x() * inv_z + f.intrinsics.cx);
    const float v = static_cast<float>(f.intrinsics.fy * pc.y() * inv_z + f.intrinsics.cy);
    if (!f.InBounds(u, v)) continue;
    const float ur = static_cast<float>(u - f.intrinsics.bf * inv_z);
    const Eigen::Vector3d po = point->position - center;
    const float dist = static_cast<float>(po.norm());
    if (dist < 0.8f * point->min_distance || dist > 1.2f * point->max_distance) continue;
    if (po.dot(point->normal) < 0.5 * dist) continue;
    const int level = point->PredictScale(dist, f.pyramid->log_scale_factor, f.pyramid->num_levels);
    const float r = radius * f.pyramid->scale_factors[level];
    int best_dist = 256;
    size_t best_idx = 0;
    f.FeaturesInArea(u, v, r, -1, -1, &candidates);
    for (size_t idx : candidates) {
      const cv::KeyPoint& kp = f.keypoints_un[idx];
      if (kp.octave < level - 1 || kp.octave > level) continue;
      const float ex = u - kp.pt.x, ey = v - kp.pt.y;
      float e2 = ex * ex + ey * ey;
      double th = kChi2Mono;
      if (f.DepthIsPrior() && f.weight_by_error_model) {
        // Network depth: weigh the depth disagreement by its error model, as the optimisers do.
        const ImageObservation obs = f.Observation(idx);
        double chi2 = e2 * obs.inv_sigma2;
        if (obs.HasDepth()) {
          const double er = ur - obs.u_right;
          chi2 += er * er * obs.DepthWeight2();
          th = kChi2Stereo;
        }
        if (chi2 > th) continue;
      } else {
        if (f.u_right[idx] >= 0) {
          const float er = ur - f.u_right[idx];
          e2 += er * er;
          th = kChi2Stereo;
        }
        if (e2 * f.pyramid->inv_level_sigma2[kp.octave] > th) continue;
      }
      const int d = DescriptorDistance(point->descriptor, f.descriptors.row(static_cast<int>(idx)));
      if (d < best_dist) {
        best_dist = d;
        best_idx = idx;
      }
    }
    if (best_dist > kOrbDistanceLow) continue;
    const std::shared_ptr<MapPoint> existing = keyframe.map_points[best_idx];
    if (existing && !existing->bad) {
      // Localisation only: a loaded map's point always survives a fusion, and two of them are
      // never merged (the loaded map does not change).
      if (existing->frozen && point->frozen) continue;
      if (existing->frozen ||
          (!point->frozen && existing->NumObservations() > point->NumObservations())) {
        map.ReplacePoint(point.get(), existing);
      } else {
        map.ReplacePoint(existing.get(), point);
      }
    } else {
      point->AddObservation(&keyframe, best_idx);
      keyframe.AddMapPoint(point, best_idx);
    }
    ++fused;
  }
  return fused;
}

int Matcher::SearchForTriangulation(const KeyFrame& k1, const KeyFrame& k2, double depth_sigmas,
                                    std::vector<std::pair<size_t, size_t>>& matches,
                                    WorkerPool* helper) const {
  const FrameFeatures& f1 = k1.F();
  const FrameFeatures& f2 = k2.F();
  const PinholeIntrinsics& in1 = f1.intrinsics;
  const PinholeIntrinsics& in2 = f2.intrinsics;
  const Rigid3d cam2_from_cam1 = k2.cam_from_world * k1.cam_from_world.inverse();
  const Eigen::Matrix3d R = cam2_from_cam1.linear();
  const Eigen::Vector3d t = cam2_from_cam1.translation();
  const Eigen::Matrix3d tx = Skew(t);
  auto inverse_k = [](const PinholeIntrinsics& in) {
    Eigen::Matrix3d k_inv = Eigen::Matrix3d::Identity();
    k_inv(0, 0) = 1.0 / in.fx;
    k_inv(1, 1) = 1.0 / in.fy;
    k_inv(0, 2) = -in.cx / in.fx;
    k_inv(1, 2) = -in.cy / in.fy;
    return k_inv;
  };
  const Eigen::Matrix3d K1inv = inverse_k(in1), K2inv = inverse_k(in2);
  // x2^T F21 x1 = 0 for pixels of the same point.
  const Eigen::Matrix3d F21 = K2inv.transpose() * tx * R * K1inv;

  std::vector<size_t> free2;
  for (size_t j = 0; j < f2.Size(); ++j) {
    if (!k2.map_points[j] || k2.map_points[j]->bad) free2.push_back(j);
  }
  auto project2 = [&](const Eigen::Vector3d& p_cam2, Eigen::Vector2d* uv) {
    if (p_cam2.z() <= 1e-6) return false;
    *uv = Eigen::Vector2d(in2.fx * p_cam2.x() / p_cam2.z() + in2.cx,
                          in2.fy * p_cam2.y() / p_cam2.z() + in2.cy);
    return true;
  };

  // Camera 1's centre seen from camera 2: near the epipole a depth is ill-defined (ORB-SLAM
  // skips matches there for keypoints without depth).
  const bool has_epipole = t.z() > 1e-9 * t.norm();
  const Eigen::Vector2d epipole = has_epipole ? Eigen::Vector2d(in2.fx * t.x() / t.z() + in2.cx,
                                                                in2.fy * t.y() / t.z() + in2.cy)
                                              : Eigen::Vector2d::Zero();
  std::vector<int> best1_for2(f2.Size(), -1), dist_for2(f2.Size(), 256);
  // Only keypoints near the epipolar line are tested (the widest band, the top level's).
  const LineSearchGrid grid2(f2.keypoints_un, free2);
  const std::vector<float>& level_sigma2 = f2.pyramid->level_sigma2;
  const double band_radius =
      std::sqrt(3.84 * *std::max_element(level_sigma2.begin(), level_sigma2.end()));
  // Each k1 keypoint's best and second-best candidate: independent of the others, so the keypoints
  // can be scanned in two halves at once; who wins a k2 keypoint is settled after, in index order.
  struct Best {
    int best = 256, second = 256;
    size_t best_j = 0;
  };
  std::vector<Best> best_for1(f1.Size());
  auto scan = [&](size_t begin, size_t end) {
    std::vector<size_t> near_line;
    for (size_t i = begin; i < end; ++i) {
      if (k1.map_points[i] && !k1.map_points[i]->bad) continue;
      const cv::KeyPoint& kp1 = f1.keypoints_un[i];
      const Eigen::Vector3d x1(kp1.pt.x, kp1.pt.y, 1.0);
      const Eigen::Vector3d line = F21 * x1;
      const double line_norm2 = line.x() * line.x() + line.y() * line.y();
      if (!(line_norm2 > 0)) continue;
      // The depth prior bounds where on the line the match can be.
      bool segment = false;
      Eigen::Vector2d seg_a, seg_b;
      if (depth_sigmas > 0 && f1.depth[i] > 0 && f1.DepthIsPrior()) {
        const double z = f1.depth[i];
        const double sigma = f1.depth_error.Sigma(z);
        const double z_near = std::max(0.05, z - depth_sigmas * sigma);
        const double z_far = z + depth_sigmas * sigma;
        const Eigen::Vector3d ray = K1inv * x1;
        segment = project2(cam2_from_cam1 * (z_near * ray), &seg_a) &&
                  project2(cam2_from_cam1 * (z_far * ray), &seg_b);
      }
      const uchar* d1 = f1.descriptors.ptr<uchar>(static_cast<int>(i));
      int best = 256, second = 256;
      size_t best_j = 0;
      grid2.Near(line, band_radius, &near_line);
      for (size_t j : near_line) {
        const cv::KeyPoint& kp2 = f2.keypoints_un[j];
        const double e = line.x() * kp2.pt.x + line.y() * kp2.pt.y + line.z();
        const double sigma2 = f2.pyramid->level_sigma2[kp2.octave];
        if (e * e / line_norm2 >= 3.84 * sigma2) continue;
        if (has_epipole && f1.monocular && f2.monocular &&
            (Eigen::Vector2d(kp2.pt.x, kp2.pt.y) - epipole).squaredNorm() <
                100.0 * f2.pyramid->scale_factors[kp2.octave])
          continue;
        if (segment) {
          const Eigen::Vector2d ab = seg_b - seg_a;
          const double len2 = ab.squaredNorm();
          const Eigen::Vector2d x2(kp2.pt.x, kp2.pt.y);
          const double s = len2 > 0 ? (x2 - seg_a).dot(ab) / len2 : 0.0;
          const double margin = 2.0 * std::sqrt(sigma2) / std::sqrt(std::max(len2, 1e-9));
          if (s < -margin || s > 1.0 + margin) continue;
        }
        const int d = DescriptorDistance(d1, f2.descriptors.ptr<uchar>(static_cast<int>(j)));
        if (d > kOrbDistanceLow) continue;
        // Ties go to the lower index: the candidates come in no particular order.
        if (d < best || (d == best && j < best_j)) {
          second = best;
          best = d;
          best_j = j;
        } else if (d < second) {
          second = d;
        }
      }
      best_for1[i] = {best, second, best_j};
    }
  };
  const size_t n1 = f1.Size();
  if (helper != nullptr && n1 >= kMinKeypointsToSplit) {
    std::future<void> second_half = helper->Submit([&] { scan(n1 / 2, n1); });
    scan(0, n1 / 2);
    second_half.get();
  } else {
    scan(0, n1);
  }
  for (size_t i = 0; i < n1; ++i) {
    const auto [best, second, best_j] = best_for1[i];
    if (best > kOrbDistanceLow || static_cast<float>(best) > nn_ratio_ * static_cast<float>(second))
      continue;
    if (best < dist_for2[best_j]) {
      dist_for2[best_j] = best;
      best1_for2[best_j] = static_cast<int>(i);
    }
  }
  RotationHistogram rotations;
  std::vector<std::pair<size_t, size_t>> found;
  for (size_t j = 0; j < f2.Size(); ++j) {
    if (best1_for2[j] < 0) continue;
    const size_t i = static_cast<size_t>(best1_for2[j]);
    rotations.Add(f1.keypoints[i].angle, f2.keypoints[j].angle, static_cast<int>(found.size()));
    found.emplace_back(i, j);
  }
  std::vector<bool> drop(found.size(), false);
  if (check_orientation_) {
    for (int k : rotations.InconsistentMatches()) drop[static_cast<size_t>(k)] = true;
  }
  int n = 0;
  for (size_t k = 0; k < found.size(); ++k) {
    if (drop[k]) continue;
    matches.push_back(found[k]);
    ++n;
  }
  return n;
}

int Matcher::SearchForInitialization(const FrameFeatures& f1, const FrameFeatures& f2,
                                     std::vector<cv::Point2f>& prev_matched,
                                     std::vector<int>& matches12, float window) const {
  matches12.assign(f1.Size(), -1);
  std::vector<int> matches21(f2.Size(), -1), distance21(f2.Size(), INT32_MAX);
  RotationHistogram rotations;
  std::vector<size_t> candidates;
  for (size_t i = 0; i < f1.Size(); ++i) {
    const cv::KeyPoint& kp1 = f1.keypoints_un[i];
    const int level = kp1.octave;
    f2.FeaturesInArea(prev_matched[i].x, prev_matched[i].y, window, level, level, &candidates);
    if (candidates.empty()) continue;
    const cv::Mat d1 = f1.descriptors.row(static_cast<int>(i));
    int best = INT32_MAX, second = INT32_MAX;
    int best_j = -1;
    for (size_t j : candidates) {
      const int d = DescriptorDistance(d1, f2.descriptors.row(static_cast<int>(j)));
      if (distance21[j] <= d) continue;  // already matched at least as well
      if (d < best) {
        second = best;
        best = d;
        best_j = static_cast<int>(j);
      } else if (d < second) {
        second = d;
      }
    }
    if (best_j < 0 || best > kOrbDistanceLow) continue;
    if (static_cast<float>(best) >= nn_ratio_ * static_cast<float>(second)) continue;
    const size_t j = static_cast<size_t>(best_j);
    if (matches21[j] >= 0) matches12[static_cast<size_t>(matches21[j])] = -1;  // taken over
    matches12[i] = best_j;
    matches21[j] = static_cast<int>(i);
    distance21[j] = best;
  }
  if (check_orientation_) {
    for (size_t i = 0; i < f1.Size(); ++i) {
      if (matches12[i] >= 0)
        rotations.Add(f1.keypoints[i].angle, f2.keypoints[static_cast<size_t>(matches12[i])].angle,
                      static_cast<int>(i));
    }
    for (int i : rotations.InconsistentMatches()) matches12[static_cast<size_t>(i)] = -1;
  }
  int n = 0;
  for (size_t i = 0; i < f1.Size(); ++i) {
    if (matches12[i] < 0) continue;
    prev_matched[i] = f2.keypoints_un[static_cast<size_t>(matches12[i])].pt;
    ++n;
  }
  return n;
}

}  // namespace ademono
