#include "ademono/slam/system.h"

#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "ademono/core/timing.h"

namespace ademono {

System::System(const Camera& camera, const SystemOptions& options)
    : camera_(camera),
      options_(options),
      extractor_(options.orb),
      pyramid_(std::make_shared<ScalePyramid>(
          ScalePyramid::Make(options.orb.num_levels, options.orb.scale_factor))),
      filter_(options.filter),
      local_mapping_(map_, options.mapping),
      tracking_(map_, local_mapping_, options) {
  camera_.Check();
  options_.Check();
}

System::~System() { Shutdown(); }

void System::Shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  local_mapping_.Shutdown();
}

std::vector<float> System::KeypointDepths(const std::vector<cv::KeyPoint>& keypoints,
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

int System::CullPointsOnMovingObjects(const Rigid3d& cam_from_world, const cv::Mat& depth,
                                       const std::vector<Detection>& moving_boxes) {
  // A map point on a moving object is left behind when the object moves on: it projects into the
  // object's box but clearly in front of the surface now visible there. Static points are the
  // visible surface (background in the box) or hidden behind the object; counting every point in
  // a box instead wipes the background around a crossing person out of the map.
  std::vector<MapPoint*> cull;
  for (const auto& [id, p] : map_.MapPoints()) {
    if (p->bad) continue;
    const Eigen::Vector3d cam = cam_from_world * p->position;
    if (!(cam.z() > 0)) continue;
    const Eigen::Vector2d uv = camera_.Project(cam);
    const int x = static_cast<int>(std::lround(uv.x())), y = static_cast<int>(std::lround(uv.y()));
    if (x < 0 || y < 0 || x >= depth.cols || y >= depth.rows) continue;
    const cv::Point2f pt(static_cast<float>(uv.x()), static_cast<float>(uv.y()));
    bool in_box = false;
    for (const Detection& d : moving_boxes) in_box = in_box || d.box.contains(pt);
    if (!in_box) continue;
    // Only a point floating in front of the visible surface has left: a static point is the
    // surface (depth agrees) or hidden behind the moving object (depth nearer).
    const float z = depth.at<float>(y, x);
    if (!(z > 0) || !std::isfinite(z) || z < 1.1 * cam.z()) continue;
    if (++p->dynamic_hits >= options_.tracking.dynamic_cull_hits) cull.push_back(p.get());
  }
  for (MapPoint* p : cull) map_.ErasePoint(p);
  return static_cast<int>(cull.size());
}

TrackResult System::TrackFrame(const FrameData& frame, const cv::Mat& depth,
                               const std::vector<Detection>& detections) {
  TrackResult result;
  result.index = frame.index;
  if (!depth.empty() && (depth.type() != CV_32FC1 || depth.size() != frame.image.size())) {
    throw std::invalid_argument("System::TrackFrame: depth must be CV_32FC1 at the image size");
  }

  auto start = std::chrono::steady_clock::now();
  cv::Mat gray;
  if (frame.image.channels() == 3) {
    cv::cvtColor(frame.image, gray, cv::COLOR_BGR2GRAY);
  } else {
    gray = frame.image;
  }
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  if (!gray.empty()) extractor_.Extract(gray, keypoints, descriptors);
  result.extraction_ms = MsSince(start);
  result.num_keypoints = static_cast<int>(keypoints.size());

  start = std::chrono::steady_clock::now();
  const std::vector<float> depths = KeypointDepths(keypoints, depth, options_.depth);
  FilterInput input;
  input.camera = &camera_;
  input.keypoints = &keypoints;
  input.descriptors = &descriptors;
  input.depths = &depths;
  input.detections = &detections;
  input.previous = previous_ ? &*previous_ : nullptr;
  {
    std::lock_guard<std::mutex> lock(map_.mutex);
    input.predicted_cam_from_world = tracking_.PredictNext();
  }
  std::vector<PointLabel> labels =
      keypoints.empty() ? std::vector<PointLabel>{} : filter_.Apply(input, &result.filter_stats);
  std::vector<cv::KeyPoint> kept_keypoints;
  cv::Mat kept_descriptors;
  std::vector<float> kept_depths;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    if (labels[i] != PointLabel::kKept) continue;
    kept_keypoints.push_back(keypoints[i]);
    kept_descriptors.push_back(descriptors.row(static_cast<int>(i)));
    kept_depths.push_back(depths[i]);
    if (depths[i] > 0) ++result.num_with_depth;
  }
  result.num_kept = static_cast<int>(kept_keypoints.size());
  result.filter_ms = MsSince(start);
  if (kept_descriptors.empty()) kept_descriptors = cv::Mat(0, 32, CV_8UC1);

  start = std::chrono::steady_clock::now();
  auto features =
      MakeFrameFeatures(camera_, pyramid_, options_.depth.virtual_baseline,
                        options_.depth.CloseDepth(), kept_keypoints, kept_descriptors, kept_depths,
                        options_.depth.ErrorModel(), options_.depth.uncertainty_weighting);
  // Map points are culled when they keep landing in dynamic boxes; only boxes the filter found
  // to hold a moving object count, so a static person's (or parked car's) points survive.
  std::vector<Detection> moving_detections;
  for (const Detection& d : detections) {
    int judged = 0, dynamic = 0;
    for (size_t i = 0; i < keypoints.size(); ++i) {
      if (labels[i] == PointLabel::kEnhancementDropped || !d.box.contains(keypoints[i].pt))
        continue;
      ++judged;
      dynamic += IsDynamic(labels[i]);
    }
    if (judged > 0 && dynamic >= options_.filter.dynamic.box_vote_ratio * judged)
      moving_detections.push_back(d);
  }
  TrackingOutput out;
  {
    std::lock_guard<std::mutex> lock(map_.mutex);
    out = tracking_.Track(features, frame.index, frame.timestamp);
    // The one rule for map points on moving objects: occlusion-aware, so it needs this frame's
    // depth map; a frame without one culls nothing (it cannot tell a left-behind point from the
    // background the box covers).
    if (out.tracked && !depth.empty() && options_.filter.enable_dynamic_removal &&
        !moving_detections.empty())
      out.dynamic_points_culled +=
          CullPointsOnMovingObjects(out.cam_from_world, depth, moving_detections);
    result.state = tracking_.State();
    if (out.new_keyframe && !frame.image.empty()) {
      // Remember colours of the points this keyframe created.
      for (size_t i = 0; i < out.new_keyframe->map_points.size(); ++i) {
        const auto& p = out.new_keyframe->map_points[i];
        if (!p || p->first_keyframe_id != out.new_keyframe->id) continue;
        const cv::Point2f& pt = out.new_keyframe->F().keypoints[i].pt;
        const int x = std::clamp(static_cast<int>(std::lround(pt.x)), 0, frame.image.cols - 1);
        const int y = std::clamp(static_cast<int>(std::lround(pt.y)), 0, frame.image.rows - 1);
        point_colors_[p->id] = frame.image.channels() == 3
                                   ? frame.image.at<cv::Vec3b>(y, x)
                                   : cv::Vec3b::all(frame.image.at<uint8_t>(y, x));
      }
      // Colours of culled points go too, so memory follows the map, not the run's length
      // (a saturated map keeps creating and culling points).
      const auto& points = map_.MapPoints();
      if (point_colors_.size() > 2 * points.size() + 1024) {
        for (auto it = point_colors_.begin(); it != point_colors_.end();)
          it = points.count(it->first) != 0 ? std::next(it) : point_colors_.erase(it);
      }
    }
  }
  result.tracking_ms = MsSince(start);
  result.tracked = out.tracked;
  result.inliers = out.inliers;
  result.relocalised = out.relocalised;
  result.dynamic_points_culled = out.dynamic_points_culled;
  result.depth_scale = out.depth_scale;
  if (out.tracked) result.cam_from_world = out.cam_from_world;

  if (out.new_keyframe) {
    result.new_keyframe = true;
    local_mapping_.InsertKeyFrame(out.new_keyframe);
  }
  // Deterministic mode has waited for this keyframe; threaded mode reports what finished meanwhile.
  result.mapping_ms = local_mapping_.TakeFinishedMilliseconds();

  // What the dynamic filter needs of this frame next time.
  // All keypoints, not only the kept ones: a point on a moving person removed in this frame must
  // still be matchable next frame, or it would come back as "unmatched, no evidence" and be kept.
  PreviousFrameFeatures previous;
  previous.keypoints = keypoints;
  previous.descriptors = descriptors.empty() ? cv::Mat(0, 32, CV_8UC1) : descriptors;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  previous.points_world.assign(keypoints.size(), Eigen::Vector3d(nan, nan, nan));
  previous.points_cam.assign(keypoints.size(), Eigen::Vector3d(nan, nan, nan));
  const Rigid3d world_from_cam = out.tracked ? out.cam_from_world.inverse() : Rigid3d::Identity();
  for (size_t i = 0; i < keypoints.size(); ++i) {
    if (!(depths[i] > 0)) continue;
    const Eigen::Vector2d un =
        camera_.Undistort(Eigen::Vector2d(keypoints[i].pt.x, keypoints[i].pt.y));
    previous.points_cam[i] = camera_.Unproject(un, depths[i]);
    if (out.tracked) previous.points_world[i] = world_from_cam * previous.points_cam[i];
  }
  previous_ = std::move(previous);

  result.keypoints = std::move(keypoints);
  result.labels = std::move(labels);
  return result;
}

Trajectory System::FrameTrajectory() const {
  std::lock_guard<std::mutex> lock(map_.mutex);
  Trajectory trajectory;
  for (const FrameRecord& r : tracking_.Records()) {
    if (!r.tracked || r.reference == nullptr) continue;
    const Rigid3d cam_from_world = Map::ResolvePose(r.reference, r.cam_from_reference);
    trajectory.push_back({r.timestamp, cam_from_world.inverse()});
  }
  return trajectory;
}

std::vector<std::pair<size_t, double>> System::DepthScales() const {
  std::lock_guard<std::mutex> lock(map_.mutex);
  std::vector<std::pair<size_t, double>> scales;
  for (const FrameRecord& r : tracking_.Records()) {
    if (r.tracked) scales.emplace_back(r.index, r.depth_scale);
  }
  return scales;
}

Trajectory System::KeyFrameTrajectory() const {
  std::lock_guard<std::mutex> lock(map_.mutex);
  Trajectory trajectory;
  for (const auto& [id, kf] : map_.KeyFrames()) {
    trajectory.push_back({kf->timestamp, kf->cam_from_world.inverse()});
  }
  return trajectory;
}

std::vector<System::ColoredPoint> System::MapPointCloud() const {
  std::lock_guard<std::mutex> lock(map_.mutex);
  std::vector<ColoredPoint> cloud;
  for (const auto& [id, p] : map_.MapPoints()) {
    if (p->bad) continue;
    auto it = point_colors_.find(id);
    cloud.push_back(
        {p->position, it == point_colors_.end() ? cv::Vec3b(255, 255, 255) : it->second});
  }
  return cloud;
}

size_t System::NumKeyFrames() const {
  std::lock_guard<std::mutex> lock(map_.mutex);
  return map_.NumKeyFrames();
}

size_t System::NumMapPoints() const {
  std::lock_guard<std::mutex> lock(map_.mutex);
  return map_.NumMapPoints();
}

int System::NumLost() const { return tracking_.NumLost(); }

int System::NumTracked() const {
  int n = 0;
  for (const FrameRecord& r : tracking_.Records()) n += r.tracked ? 1 : 0;
  return n;
}

}  // namespace ademono
