#include "ademono/filter/dynamic.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <stdexcept>

#include "ademono/core/cv_geometry.h"
#include "ademono/feature/matching.h"

namespace ademono {

bool InsideBox(const cv::Rect2f& box, const cv::Point2f& p) {
  return p.x >= box.x && p.x < box.x + box.width && p.y >= box.y && p.y < box.y + box.height;
}

std::vector<GrownBox> GrowDynamicBoxes(const std::vector<Detection>& detections,
                                       cv::Size image_size, const DynamicParams& params) {
  std::vector<GrownBox> boxes;
  const double image_area = static_cast<double>(image_size.width) * image_size.height;
  for (size_t i = 0; i < detections.size(); ++i) {
    const Detection& det = detections[i];
    if (std::find(params.dynamic_class_ids.begin(), params.dynamic_class_ids.end(), det.class_id) ==
        params.dynamic_class_ids.end())
      continue;
    const cv::Rect2f& b = det.box;
    if (!(b.width > 0.f) || !(b.height > 0.f) || !std::isfinite(b.x) || !std::isfinite(b.y))
      continue;
    const double d = params.box_growth * std::hypot(b.width, b.height);
    const double x0 = std::max(0.0, b.x - d), y0 = std::max(0.0, b.y - d);
    const double x1 = std::min<double>(image_size.width, b.x + b.width + d);
    const double y1 = std::min<double>(image_size.height, b.y + b.height + d);
    if (x1 <= x0 || y1 <= y0) continue;
    GrownBox grown;
    grown.box = cv::Rect2f(static_cast<float>(x0), static_cast<float>(y0),
                           static_cast<float>(x1 - x0), static_cast<float>(y1 - y0));
    // Size class from the detector's own box, before growth and clipping.
    grown.small =
        static_cast<double>(b.width) * b.height / image_area < params.small_box_area_ratio;
    grown.detection_index = static_cast<int>(i);
    boxes.push_back(grown);
  }
  return boxes;
}

std::optional<Rigid3d> FitBackgroundMotion(const std::vector<cv::KeyPoint>& keypoints,
                                           const PreviousFrameFeatures& previous,
                                           const std::vector<cv::DMatch>& matches,
                                           const std::vector<char>& in_box, const Camera& camera,
                                           const DynamicParams& params, int* num_inliers) {
  std::vector<cv::Point3f> object;
  std::vector<cv::Point2f> image;
  for (const cv::DMatch& m : matches) {
    const size_t i = static_cast<size_t>(m.queryIdx);
    if (in_box[i]) continue;
    const Eigen::Vector3d& x = previous.points_cam[static_cast<size_t>(m.trainIdx)];
    const cv::Point2f& p = keypoints[i].pt;
    if (!x.allFinite() || !(x.z() > 0.0) || !std::isfinite(p.x) || !std::isfinite(p.y)) continue;
    const Eigen::Vector2d un = camera.Undistort(Eigen::Vector2d(p.x, p.y));
    object.emplace_back(static_cast<float>(x.x()), static_cast<float>(x.y()),
                        static_cast<float>(x.z()));
    image.emplace_back(static_cast<float>(un.x()), static_cast<float>(un.y()));
  }
  if (static_cast<int>(object.size()) < params.motion_min_inliers) return std::nullopt;
  const cv::Mat K =
      (cv::Mat_<double>(3, 3) << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  // OpenCV's RANSAC seeds its own generator with a constant: deterministic for the same input.
  if (!cv::solvePnPRansac(
          object, image, K, cv::noArray(), rvec, tvec, false, params.motion_ransac_iterations,
          static_cast<float>(params.motion_inlier_px), 0.99, inliers, cv::SOLVEPNP_EPNP) ||
      static_cast<int>(inliers.size()) < params.motion_min_inliers)
    return std::nullopt;
  std::vector<cv::Point3f> inlier_object;
  std::vector<cv::Point2f> inlier_image;
  for (int k : inliers) {
    inlier_object.push_back(object[static_cast<size_t>(k)]);
    inlier_image.push_back(image[static_cast<size_t>(k)]);
  }
  cv::solvePnPRefineLM(inlier_object, inlier_image, K, cv::noArray(), rvec, tvec);
  const Rigid3d cur_from_prev = RigidFromRodrigues(rvec, tvec);
  if (!cur_from_prev.matrix().allFinite()) return std::nullopt;
  if (num_inliers != nullptr) *num_inliers = static_cast<int>(inliers.size());
  return cur_from_prev;
}

DynamicResult RemoveDynamicPoints(const DynamicInput& input, const DynamicParams& params) {
  if (input.keypoints == nullptr || input.camera == nullptr)
    throw std::invalid_argument("RemoveDynamicPoints: keypoints and camera are required");
  const std::vector<cv::KeyPoint>& kps = *input.keypoints;
  const size_t n = kps.size();
  if (!input.active.empty() && input.active.size() != n)
    throw std::invalid_argument("RemoveDynamicPoints: one active flag per keypoint expected");
  auto active = [&](size_t i) { return input.active.empty() || input.active[i]; };

  DynamicResult result;
  result.labels.assign(n, PointLabel::kKept);
  if (input.detections != nullptr)
    result.boxes = GrowDynamicBoxes(*input.detections,
                                    cv::Size(input.camera->width, input.camera->height), params);
  if (result.boxes.empty()) return result;

  // Which box class each point falls in: a small box wins over a large one. Judged small boxes
  // go through the large boxes' tests.
  auto dropped_whole = [&](const GrownBox& b) { return b.small && !params.judge_small_boxes; };
  std::vector<char> in_small(n, 0), in_large(n, 0), in_any(n, 0);
  for (size_t i = 0; i < n; ++i) {
    for (const GrownBox& b : result.boxes) {
      if (!InsideBox(b.box, kps[i].pt)) continue;
      in_any[i] = 1;
      (dropped_whole(b) ? in_small[i] : in_large[i]) = 1;
    }
  }
  bool any_large = false;
  for (size_t i = 0; i < n; ++i) {
    if (!active(i)) continue;
    if (in_small[i])
      result.labels[i] = PointLabel::kDynamicSmallBox;
    else if (in_large[i])
      any_large = true;
  }
  if (!any_large || input.previous == nullptr) return result;  // large-box points stay kept

  const PreviousFrameFeatures& prev = *input.previous;
  if (input.descriptors == nullptr || input.descriptors->rows != static_cast<int>(n))
    throw std::invalid_argument("RemoveDynamicPoints: one descriptor row per keypoint expected");
  if (prev.descriptors.rows != static_cast<int>(prev.keypoints.size()))
    throw std::invalid_argument(
        "RemoveDynamicPoints: previous frame needs one descriptor row per keypoint");
  if (!prev.points_world.empty() && prev.points_world.size() != prev.keypoints.size())
    throw std::invalid_argument(
        "RemoveDynamicPoints: previous frame needs one world point per keypoint (NaN if none)");
  if (!prev.points_cam.empty() && prev.points_cam.size() != prev.keypoints.size())
    throw std::invalid_argument(
        "RemoveDynamicPoints: previous frame needs one camera point per keypoint (NaN if none)");
  if (input.depths != nullptr && input.depths->size() != n)
    throw std::invalid_argument("RemoveDynamicPoints: one depth per keypoint expected");

  // Match the active current points to the previous frame.
  std::vector<int> query_to_point;
  cv::Mat query;
  for (size_t i = 0; i < n; ++i) {
    if (!active(i) || result.labels[i] != PointLabel::kKept) continue;
    query_to_point.push_back(static_cast<int>(i));
    query.push_back(input.descriptors->row(static_cast<int>(i)));
  }
  BruteForceMatchOptions match_options;
  match_options.ratio = params.match_ratio;
  match_options.max_distance = params.match_max_distance;
  std::vector<cv::DMatch> matches = MatchBruteForce(query, prev.descriptors, match_options);
  std::vector<int> prev_of(n, -1);
  for (cv::DMatch& m : matches) {
    m.queryIdx = query_to_point[static_cast<size_t>(m.queryIdx)];
    prev_of[static_cast<size_t>(m.queryIdx)] = m.trainIdx;
  }

  // Stage 1's background motion model. The paper's: one mean image displacement. With motion
  // compensation: the camera motion fitted to the background matches that have a depth in the
  // previous frame (PnP + RANSAC), so each point is compared with where a static point at its
  // depth would be now. Falls back to the paper's model when the fit is not possible.
  auto finite = [](const cv::Point2f& p) { return std::isfinite(p.x) && std::isfinite(p.y); };
  std::optional<Rigid3d> cur_from_prev;
  if (params.stage1_motion_compensation && !prev.points_cam.empty())
    cur_from_prev = FitBackgroundMotion(kps, prev, matches, in_any, *input.camera, params,
                                        &result.num_motion_inliers);
  result.motion_compensated = cur_from_prev.has_value();
  const std::optional<Rigid3d> prev_from_cur =
      cur_from_prev ? std::optional<Rigid3d>(cur_from_prev->inverse()) : std::nullopt;
  auto displacement = [&](size_t i, int j) -> std::optional<Eigen::Vector2d> {
    const cv::Point2f& q = prev.keypoints[static_cast<size_t>(j)].pt;
    if (!finite(kps[i].pt) || !finite(q))
      return std::nullopt;  // a NaN would poison the background mean and disable stage 1
    const Eigen::Vector2d cur_px(kps[i].pt.x, kps[i].pt.y), prev_px(q.x, q.y);
    if (!cur_from_prev) return cur_px - prev_px;
    // Forward: the previous point moved with the camera, against where it is now.
    const Eigen::Vector3d& x = prev.points_cam[static_cast<size_t>(j)];
    if (x.allFinite()) {
      const Eigen::Vector3d cam = *cur_from_prev * x;
      if (!(cam.z() > 0.0)) return std::nullopt;
      return cur_px - input.camera->Project(cam);
    }
    // Backward, from the current depth: where a static point would have been, against where it
    // was (the same residual as forward, to first order).
    if (input.depths == nullptr) return std::nullopt;
    const float z = (*input.depths)[i];
    if (!(z > 0.f) || !std::isfinite(z)) return std::nullopt;  // no depth in either frame
    const Eigen::Vector3d cam =
        *prev_from_cur * input.camera->Unproject(input.camera->Undistort(cur_px), z);
    if (!(cam.z() > 0.0)) return std::nullopt;
    return input.camera->Project(cam) - prev_px;
  };

  // Background motion: mean displacement of the t closest matches outside every grown box (with
  // compensation, the mean residual of the fitted motion: near zero unless the fit is biased).
  {
    std::vector<std::pair<const cv::DMatch*, Eigen::Vector2d>> background;
    for (const cv::DMatch& m : matches) {
      const size_t i = static_cast<size_t>(m.queryIdx);
      if (in_any[i]) continue;
      if (const auto d = displacement(i, m.trainIdx)) background.emplace_back(&m, *d);
    }
    std::stable_sort(background.begin(), background.end(), [](const auto& a, const auto& b) {
      return a.first->distance < b.first->distance;
    });
    if (background.size() > static_cast<size_t>(params.background_matches_t))
      background.resize(static_cast<size_t>(params.background_matches_t));
    if (!background.empty()) {
      Eigen::Vector2d sum = Eigen::Vector2d::Zero();
      for (const auto& [m, d] : background) sum += d;
      result.background_motion = sum / static_cast<double>(background.size());
      result.num_background_matches = static_cast<int>(background.size());
    }
  }

  // judged: the point got a verdict from stage 1 or 2 (the box vote counts only those).
  std::vector<char> judged(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!active(i) || !in_large[i] || result.labels[i] != PointLabel::kKept) continue;
    const int j = prev_of[i];
    if (j < 0) continue;  // unmatched: no evidence either way, kept
    // Stage 1: displacement against the background's.
    if (result.background_motion) {
      if (const auto d = displacement(i, j)) {
        judged[i] = 1;
        if ((*d - *result.background_motion).norm() > params.d_dis_px) {
          result.labels[i] = PointLabel::kDynamicStage1;
          continue;
        }
      }
    } else {
      judged[i] = 1;  // no background match at all: stage 1 passes the point
    }
    // Stage 2: where the previous world point should appear under the predicted pose.
    if (!input.predicted_cam_from_world || prev.points_world.empty()) continue;
    const Eigen::Vector3d& world = prev.points_world[static_cast<size_t>(j)];
    if (!world.allFinite()) continue;
    judged[i] = 1;
    const Eigen::Vector3d cam = *input.predicted_cam_from_world * world;
    if (!(cam.z() > 0.0)) {
      // A static point seen last frame cannot jump behind the camera under smooth motion.
      result.labels[i] = PointLabel::kDynamicStage2;
      continue;
    }
    const Eigen::Vector2d projected = input.camera->Project(cam);
    const Eigen::Vector2d observed(kps[i].pt.x, kps[i].pt.y);
    if ((projected - observed).norm() > params.d_min_px)
      result.labels[i] = PointLabel::kDynamicStage2;
  }

  // Box vote: a point without a verdict (no match, or nothing to compare it with) has no evidence
  // of its own, but if enough of the judged points of its large box failed stage 1 or 2 the box
  // holds a moving object, and the unjudged points (mostly on the object: its texture and
  // silhouette change frame to frame) go with it. A static object's box keeps them.
  // A box is larger than its mover: the background seen around a walker inside the grown box is
  // unjudged too (on the photo-actor office most of the static points removed were these), so a
  // point clearly behind the mover's depth is spared and left to the tracker's geometric test.
  if (params.box_vote_ratio <= 1.0) {
    std::vector<char> moving_box(result.boxes.size(), 0);
    std::vector<double> mover_depth(result.boxes.size(), 0.0);  // 0: unknown
    for (size_t b = 0; b < result.boxes.size(); ++b) {
      if (dropped_whole(result.boxes[b])) continue;
      int num_judged = 0, num_dynamic = 0;
      std::vector<float> failed_depths;
      for (size_t i = 0; i < n; ++i) {
        if (!active(i) || !judged[i] || !InsideBox(result.boxes[b].box, kps[i].pt)) continue;
        ++num_judged;
        if (result.labels[i] == PointLabel::kDynamicStage1 ||
            result.labels[i] == PointLabel::kDynamicStage2) {
          ++num_dynamic;
          const float z = input.depths != nullptr ? (*input.depths)[i] : 0.f;
          if (z > 0.f && std::isfinite(z)) failed_depths.push_back(z);
        }
      }
      moving_box[b] = num_judged >= params.box_vote_min_matches &&
                      num_dynamic >= params.box_vote_ratio * static_cast<double>(num_judged);
      if (moving_box[b] && failed_depths.size() >= 3) {
        const auto mid =
            failed_depths.begin() + static_cast<std::ptrdiff_t>(failed_depths.size() / 2);
        std::nth_element(failed_depths.begin(), mid, failed_depths.end());
        mover_depth[b] = *mid;
      }
    }
    for (size_t i = 0; i < n; ++i) {
      if (!active(i) || !in_large[i] || judged[i] || result.labels[i] != PointLabel::kKept)
        continue;
      const float z = input.depths != nullptr ? (*input.depths)[i] : 0.f;
      for (size_t b = 0; b < result.boxes.size(); ++b) {
        if (!moving_box[b] || !InsideBox(result.boxes[b].box, kps[i].pt)) continue;
        const bool behind = params.box_vote_depth_ratio > 0.0 && mover_depth[b] > 0.0 && z > 0.f &&
                            std::isfinite(z) && z > params.box_vote_depth_ratio * mover_depth[b];
        if (behind) continue;  // background seen inside this box; another box may still claim it
        result.labels[i] = PointLabel::kDynamicBoxVote;
        break;
      }
    }
  }
  return result;
}

}  // namespace ademono
