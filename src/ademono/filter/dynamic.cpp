#include "ademono/filter/dynamic.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

  // Which box class each point falls in: a small box wins over a large one.
  std::vector<char> in_small(n, 0), in_large(n, 0), in_any(n, 0);
  for (size_t i = 0; i < n; ++i) {
    for (const GrownBox& b : result.boxes) {
      if (!InsideBox(b.box, kps[i].pt)) continue;
      in_any[i] = 1;
      (b.small ? in_small[i] : in_large[i]) = 1;
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

  // Background motion: mean displacement of the t closest matches outside every grown box.
  std::vector<cv::DMatch> background;
  auto finite = [](const cv::Point2f& p) { return std::isfinite(p.x) && std::isfinite(p.y); };
  for (const cv::DMatch& m : matches) {
    // Non-finite positions would turn the mean into NaN and silently disable stage 1.
    if (!in_any[static_cast<size_t>(m.queryIdx)] &&
        finite(kps[static_cast<size_t>(m.queryIdx)].pt) &&
        finite(prev.keypoints[static_cast<size_t>(m.trainIdx)].pt))
      background.push_back(m);
  }
  std::stable_sort(
      background.begin(), background.end(),
      [](const cv::DMatch& a, const cv::DMatch& b) { return a.distance < b.distance; });
  if (background.size() > static_cast<size_t>(params.background_matches_t))
    background.resize(static_cast<size_t>(params.background_matches_t));
  if (!background.empty()) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (const cv::DMatch& m : background) {
      const cv::Point2f d = kps[static_cast<size_t>(m.queryIdx)].pt - prev.keypoints[m.trainIdx].pt;
      sum += Eigen::Vector2d(d.x, d.y);
    }
    result.background_motion = sum / static_cast<double>(background.size());
    result.num_background_matches = static_cast<int>(background.size());
  }

  for (size_t i = 0; i < n; ++i) {
    if (!active(i) || !in_large[i] || result.labels[i] != PointLabel::kKept) continue;
    const int j = prev_of[i];
    if (j < 0) continue;  // unmatched: no evidence either way, kept
    // Stage 1: displacement against the background's.
    if (result.background_motion) {
      const cv::Point2f d = kps[i].pt - prev.keypoints[static_cast<size_t>(j)].pt;
      const Eigen::Vector2d diff = Eigen::Vector2d(d.x, d.y) - *result.background_motion;
      if (diff.norm() > params.d_dis_px) {
        result.labels[i] = PointLabel::kDynamicStage1;
        continue;
      }
    }
    // Stage 2: where the previous world point should appear under the predicted pose.
    if (!input.predicted_cam_from_world || prev.points_world.empty()) continue;
    const Eigen::Vector3d& world = prev.points_world[static_cast<size_t>(j)];
    if (!world.allFinite()) continue;
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

  // Box vote: a point without a match has no evidence of its own, but if enough of the matched
  // points of its large box failed stage 1 or 2 the box holds a moving object, and the unmatched
  // points (mostly on the object: its texture and silhouette change frame to frame) go with it.
  // A static object's box (few failures) keeps its unmatched points.
  if (params.box_vote_ratio <= 1.0) {
    std::vector<char> moving_box(result.boxes.size(), 0);
    for (size_t b = 0; b < result.boxes.size(); ++b) {
      if (result.boxes[b].small) continue;
      int judged = 0, dynamic = 0;
      for (size_t i = 0; i < n; ++i) {
        if (!active(i) || prev_of[i] < 0 || !InsideBox(result.boxes[b].box, kps[i].pt)) continue;
        ++judged;
        if (result.labels[i] == PointLabel::kDynamicStage1 ||
            result.labels[i] == PointLabel::kDynamicStage2)
          ++dynamic;
      }
      moving_box[b] = judged >= params.box_vote_min_matches &&
                      dynamic >= params.box_vote_ratio * static_cast<double>(judged);
    }
    for (size_t i = 0; i < n; ++i) {
      if (!active(i) || !in_large[i] || prev_of[i] >= 0 || result.labels[i] != PointLabel::kKept)
        continue;
      for (size_t b = 0; b < result.boxes.size(); ++b) {
        if (moving_box[b] && InsideBox(result.boxes[b].box, kps[i].pt)) {
          result.labels[i] = PointLabel::kDynamicBoxVote;
          break;
        }
      }
    }
  }
  return result;
}

}  // namespace ademono
