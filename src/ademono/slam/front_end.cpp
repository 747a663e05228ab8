#include "ademono/slam/front_end.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "ademono/core/timing.h"
#include "ademono/filter/dynamic.h"

namespace ademono {

FrontEnd::FrontEnd(const Camera& camera, const SystemOptions& options)
    : camera_(camera),
      options_(options),
      extractor_(options.orb),
      pyramid_(std::make_shared<ScalePyramid>(
          ScalePyramid::Make(options.orb.num_levels, options.orb.scale_factor))),
      filter_(options.filter) {}

ExtractedFrame FrontEnd::Extract(const FrameData& frame, const cv::Mat& depth) const {
  ExtractedFrame out = ExtractFeatures(frame);
  AddDepths(out, depth);
  return out;
}

ExtractedFrame FrontEnd::ExtractFeatures(const FrameData& frame) const {
  ExtractedFrame out;
  auto start = std::chrono::steady_clock::now();
  cv::Mat gray;
  if (frame.image.channels() == 3) {
    cv::cvtColor(frame.image, gray, cv::COLOR_BGR2GRAY);
  } else {
    gray = frame.image;
  }
  if (!gray.empty()) extractor_.Extract(gray, out.keypoints, out.descriptors);
  out.extraction_ms = MsSince(start);
  return out;
}

void FrontEnd::AddDepths(ExtractedFrame& extracted, const cv::Mat& depth) const {
  const auto start = std::chrono::steady_clock::now();
  extracted.depths = KeypointDepths(extracted.keypoints, depth, options_.depth);
  extracted.depth_ms = MsSince(start);
}

FilteredFrame FrontEnd::Filter(const ExtractedFrame& extracted,
                               const std::vector<Detection>& detections,
                               const std::optional<Rigid3d>& predicted_cam_from_world) {
  FilteredFrame out;
  auto start = std::chrono::steady_clock::now();
  const std::vector<cv::KeyPoint>& keypoints = extracted.keypoints;
  const std::vector<float>& depths = extracted.depths;
  FilterInput input;
  input.camera = &camera_;
  input.keypoints = &keypoints;
  input.descriptors = &extracted.descriptors;
  input.depths = &depths;
  input.detections = &detections;
  input.previous = previous_ ? &*previous_ : nullptr;
  input.predicted_cam_from_world = predicted_cam_from_world;
  out.labels =
      keypoints.empty() ? std::vector<PointLabel>{} : filter_.Apply(input, &out.filter_stats);
  std::vector<cv::KeyPoint> kept_keypoints;
  cv::Mat kept_descriptors;
  std::vector<float> kept_depths;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    if (!FeedsTracking(out.labels[i], options_.filter)) continue;
    kept_keypoints.push_back(keypoints[i]);
    kept_descriptors.push_back(extracted.descriptors.row(static_cast<int>(i)));
    kept_depths.push_back(out.labels[i] == PointLabel::kKept ? depths[i] : 0.f);
    if (kept_depths.back() > 0) ++out.num_with_depth;
  }
  out.num_kept = static_cast<int>(kept_keypoints.size());
  out.filter_ms = MsSince(start);
  if (kept_descriptors.empty()) kept_descriptors = cv::Mat(0, 32, CV_8UC1);

  start = std::chrono::steady_clock::now();
  out.features =
      MakeFrameFeatures(camera_, pyramid_, options_.depth.virtual_baseline,
                        options_.depth.CloseDepth(), kept_keypoints, kept_descriptors, kept_depths,
                        options_.depth.ErrorModel(), options_.depth.uncertainty_weighting,
                        options_.tracking.monocular);
  // Map points are culled when they keep landing in dynamic boxes; only boxes the filter found
  // to hold a moving object count, so a static person's (or parked car's) points survive.
  for (const Detection& d : detections) {
    int judged = 0, dynamic = 0;
    for (size_t i = 0; i < keypoints.size(); ++i) {
      if (out.labels[i] == PointLabel::kEnhancementDropped || !d.box.contains(keypoints[i].pt))
        continue;
      ++judged;
      dynamic += IsDynamic(out.labels[i]);
    }
    if (judged > 0 && dynamic >= options_.filter.dynamic.box_vote_ratio * judged)
      out.moving_detections.push_back(d);
  }
  // Kept keypoints inside a dynamic-class box (grown as the filter grows them): the geometric
  // test starts the map points made from them at the lower box prior; without the test, a first
  // map leaves them out (tracking.first_map_box_prior).
  if (options_.filter.enable_dynamic_removal &&
      (options_.tracking.static_test || options_.tracking.first_map_box_prior)) {
    const std::vector<GrownBox> boxes = GrowDynamicBoxes(
        detections, cv::Size(camera_.width, camera_.height), options_.filter.dynamic);
    if (!boxes.empty()) {
      for (const cv::KeyPoint& kp : kept_keypoints) {
        bool inside = false;
        for (const GrownBox& b : boxes) inside = inside || InsideBox(b.box, kp.pt);
        out.in_dynamic_box.push_back(inside ? 1 : 0);
      }
    }
  }
  out.features_ms = MsSince(start);
  return out;
}

void FrontEnd::Remember(const ExtractedFrame& extracted,
                        const std::optional<Rigid3d>& cam_from_world) {
  // All keypoints, not only the kept ones: a point on a moving person removed in this frame must
  // still be matchable next frame, or it would come back as "unmatched, no evidence" and be kept.
  const std::vector<cv::KeyPoint>& keypoints = extracted.keypoints;
  PreviousFrameFeatures previous;
  previous.keypoints = keypoints;
  previous.descriptors =
      extracted.descriptors.empty() ? cv::Mat(0, 32, CV_8UC1) : extracted.descriptors;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  previous.points_world.assign(keypoints.size(), Eigen::Vector3d(nan, nan, nan));
  previous.points_cam.assign(keypoints.size(), Eigen::Vector3d(nan, nan, nan));
  previous.cam_from_world = cam_from_world;
  const Rigid3d world_from_cam = cam_from_world ? cam_from_world->inverse() : Rigid3d::Identity();
  for (size_t i = 0; i < keypoints.size(); ++i) {
    if (!(extracted.depths[i] > 0)) continue;
    const Eigen::Vector2d un =
        camera_.Undistort(Eigen::Vector2d(keypoints[i].pt.x, keypoints[i].pt.y));
    previous.points_cam[i] = camera_.Unproject(un, extracted.depths[i]);
    if (cam_from_world) previous.points_world[i] = world_from_cam * previous.points_cam[i];
  }
  previous_ = std::move(previous);
}

std::vector<float> FrontEnd::KeypointDepths(const std::vector<cv::KeyPoint>& keypoints,
                                          const cv::Mat& depth, const FrameDepthOptions& options) {
  std::vector<float> result(keypoints.size(), -1.f);
  if (depth.empty()) return result;
  const int r = options.edge_radius;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const int x = static_cast<int>(std::lround(keypoints[i].pt.x));
    const int y = static_cast<int>(std::lround(keypoints[i].pt.y));
    if (x < 0 || y < 0 || x >= depth.cols || y >= depth.rows) continue;
    const float z = depth.at<float>(y, x);
    if (!std::isfinite(z) || z < options.min_depth || z > options.max_depth) continue;
    if (options.IsPrior()) {
      // Smooth network depth has no holes and blurs object boundaries into ramps: drop depth
      // where it changes steeply across the keypoint (it is neither object nor background).
      if (r > 0 && options.edge_relative_slope > 0) {
        auto at = [&](int xx, int yy) {
          xx = std::clamp(xx, 0, depth.cols - 1);
          yy = std::clamp(yy, 0, depth.rows - 1);
          return depth.at<float>(yy, xx);
        };
        const float dx = std::abs(at(x + r, y) - at(x - r, y));
        const float dy = std::abs(at(x, y + r) - at(x, y - r));
        if (!(std::max(dx, dy) <= options.edge_relative_slope * z)) continue;
      }
      result[i] = z;
      continue;
    }
    if (r > 0) {
      // Depth at an object boundary is unreliable (and, unregistered, may belong to the other
      // side): require a locally consistent neighbourhood.
      float lo = z, hi = z;
      bool hole = false;
      for (int dy = -r; dy <= r && !hole; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= depth.rows) continue;
        const float* row = depth.ptr<float>(yy);
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= depth.cols) continue;
          const float d = row[xx];
          if (!(d > 0.f) || !std::isfinite(d)) {
            hole = true;
            break;
          }
          lo = std::min(lo, d);
          hi = std::max(hi, d);
        }
      }
      if (hole || hi - lo > options.edge_relative_jump * z) continue;
    }
    result[i] = z;
  }
  return result;
}

}  // namespace ademono
