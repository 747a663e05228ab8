#include "ademono/slam/monocular_initialization.h"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "ademono/core/statistics.h"
#include "ademono/optimize/bundle_adjustment.h"
#include "ademono/slam/keyframe.h"
#include "ademono/slam/matcher.h"

namespace ademono {

std::optional<MonocularInitialization::Keyframes> MonocularInitialization::Add(Frame& frame,
                                                                                 Map& map) {
  const TrackingOptions& t = options_.tracking;
  const FrameFeatures& f2 = frame.F();
  const auto min_keypoints = static_cast<size_t>(t.init_min_matches);
  if (!reference_ || f2.Size() <= min_keypoints) {
    reference_.reset();
    if (f2.Size() > min_keypoints) {
      reference_ = frame;
      prev_matched_.clear();
      for (const cv::KeyPoint& kp : f2.keypoints_un) prev_matched_.push_back(kp.pt);
    }
    return std::nullopt;
  }
  const FrameFeatures& f1 = reference_->F();
  std::vector<int> matches12;
  const Matcher matcher(0.9f, true);
  const int n = matcher.SearchForInitialization(f1, f2, prev_matched_, matches12,
                                                static_cast<float>(t.init_search_radius));
  if (n < t.init_min_matches) {
    // The view has moved on: start again from this frame.
    reference_ = frame;
    prev_matched_.clear();
    for (const cv::KeyPoint& kp : f2.keypoints_un) prev_matched_.push_back(kp.pt);
    return std::nullopt;
  }
  std::vector<Eigen::Vector2d> pixels1, pixels2;
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t i = 0; i < matches12.size(); ++i) {
    if (matches12[i] < 0) continue;
    const size_t j = static_cast<size_t>(matches12[i]);
    pixels1.emplace_back(f1.keypoints_un[i].pt.x, f1.keypoints_un[i].pt.y);
    pixels2.emplace_back(f2.keypoints_un[j].pt.x, f2.keypoints_un[j].pt.y);
    pairs.emplace_back(i, j);
  }
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  K(0, 0) = f1.intrinsics.fx;
  K(1, 1) = f1.intrinsics.fy;
  K(0, 2) = f1.intrinsics.cx;
  K(1, 2) = f1.intrinsics.cy;
  last_ = InitializeTwoView(K, pixels1, pixels2, options_.initializer);
  spdlog::debug("frame {}: two-view with frame {}: {} matches, R_H {:.2f}, {} ({})", frame.index,
                reference_->index, n, last_.homography_ratio, TwoViewModelName(last_.model),
                last_.valid ? "ok" : last_.failure);
  if (!last_.valid) return std::nullopt;

  // Bundle adjustment of the two views before anything enters the map (ORB-SLAM's global BA of
  // the initial map), the first camera fixed.
  BundleAdjustmentProblem problem;
  problem.intrinsics = f1.intrinsics;
  problem.cameras.push_back({Rigid3d::Identity(), true});
  problem.cameras.push_back({last_.cam2_from_cam1, false});
  std::vector<size_t> kept;  // index into pairs
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (!last_.triangulated[k]) continue;
    const size_t point = problem.points.size();
    problem.points.push_back(last_.points_cam1[k]);
    problem.observations.push_back({0, point, f1.Observation(pairs[k].first)});
    problem.observations.push_back({1, point, f2.Observation(pairs[k].second)});
    kept.push_back(k);
  }
  BundleAdjustmentOptions ba = options_.mapping.ba;
  ba.first_iterations = 20;
  ba.second_iterations = 10;
  const BundleAdjustmentResult solved = SolveBundleAdjustment(problem, ba);
  std::vector<double> depths;
  std::vector<uint8_t> good(kept.size(), 0);
  const Rigid3d cam2_from_cam1 = solved.cam_from_world[1];
  for (size_t k = 0; k < kept.size(); ++k) {
    if (solved.outlier[2 * k] || solved.outlier[2 * k + 1]) continue;
    const Eigen::Vector3d& x = solved.points[k];
    if (!(x.z() > 0) || !((cam2_from_cam1 * x).z() > 0)) continue;
    good[k] = 1;
    depths.push_back(x.z());
  }
  {
    std::vector<Eigen::Vector3d> points;
    std::vector<Eigen::Vector2d> q1, q2;
    for (size_t k = 0; k < kept.size(); ++k) {
      if (!good[k]) continue;
      points.push_back(solved.points[k]);
      q1.push_back(pixels1[kept[k]]);
      q2.push_back(pixels2[kept[k]]);
    }
    const double sigma_deg = TranslationDirectionSigmaDeg(K, cam2_from_cam1, points, q1, q2);
    spdlog::debug("frame {}: two-view translation direction sigma {:.2f} deg", frame.index,
                  sigma_deg);
    if (sigma_deg > options_.initializer.max_direction_sigma_deg) {
      last_.valid = false;
      last_.failure = "translation direction uncertain";
      return std::nullopt;
    }
  }
  const double median_depth = Median(depths);
  if (!(median_depth > 0) || static_cast<int>(depths.size()) < t.init_min_matches) {
    spdlog::debug("frame {}: two-view map refused ({} points after BA)", frame.index,
                  depths.size());
    last_.valid = false;
    last_.failure = "too few points after bundle adjustment";
    return std::nullopt;
  }
  // Scale-free: the first keyframe's median scene depth is 1.
  const double inv = 1.0 / median_depth;
  reference_->cam_from_world = Rigid3d::Identity();
  Rigid3d pose2 = cam2_from_cam1;
  pose2.translation() *= inv;
  frame.cam_from_world = pose2;
  std::shared_ptr<KeyFrame> kf1 = map.CreateKeyFrame(*reference_);
  std::shared_ptr<KeyFrame> kf2 = map.CreateKeyFrame(frame);
  frame.map_points.assign(f2.Size(), nullptr);
  frame.outlier.assign(f2.Size(), false);
  for (size_t k = 0; k < kept.size(); ++k) {
    if (!good[k]) continue;
    const auto [i, j] = pairs[kept[k]];
    auto point = map.CreateMapPoint(solved.points[k] * inv, kf1.get(), reference_->id);
    point->AddObservation(kf1.get(), i);
    point->AddObservation(kf2.get(), j);
    kf1->AddMapPoint(point, i);
    kf2->AddMapPoint(point, j);
    point->ComputeDistinctiveDescriptor();
    point->UpdateNormalAndDepth();
    frame.map_points[j] = point;
  }
  kf1->UpdateConnections();
  kf2->UpdateConnections();
  spdlog::info("map initialised from frames {} and {} ({}, {} points, parallax {:.1f} deg)",
               reference_->index, frame.index, TwoViewModelName(last_.model), depths.size(),
               last_.parallax_deg);
  reference_.reset();
  return Keyframes{kf1, kf2};
}

}  // namespace ademono
