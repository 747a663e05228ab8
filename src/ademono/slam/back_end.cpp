#include "ademono/slam/back_end.h"

#include <chrono>
#include <cmath>

#include "ademono/core/timing.h"

namespace ademono {

BackEnd::BackEnd(const Camera& camera, const SystemOptions& options)
    : camera_(camera),
      options_(options),
      local_mapping_(map_, options.mapping),
      tracking_(map_, local_mapping_, options) {}

BackEnd::~BackEnd() { Shutdown(); }

void BackEnd::Shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  local_mapping_.Shutdown();
}

void BackEnd::HandOff() { local_mapping_.HandOff(frames_); }

std::optional<Rigid3d> BackEnd::PredictNext() const {
  std::lock_guard<std::mutex> lock(map_.mutex);
  return tracking_.PredictNext();
}

int BackEnd::CullPointsOnMovingObjects(const Rigid3d& cam_from_world, const cv::Mat& depth,
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

BackEndResult BackEnd::Track(const FrameData& frame, const cv::Mat& depth,
                             const FilteredFrame& filtered) {
  BackEndResult result;
  const auto start = std::chrono::steady_clock::now();
  TrackingOutput& out = result.tracking;
  {
    std::lock_guard<std::mutex> lock(map_.mutex);
    out = tracking_.Track(filtered.features, frame.index, frame.timestamp);
    // The one rule for map points on moving objects: occlusion-aware, so it needs this frame's
    // depth map; a frame without one culls nothing (it cannot tell a left-behind point from the
    // background the box covers).
    if (out.tracked && !depth.empty() && options_.filter.enable_dynamic_removal &&
        !filtered.moving_detections.empty())
      out.dynamic_points_culled +=
          CullPointsOnMovingObjects(out.cam_from_world, depth, filtered.moving_detections);
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
    }
  }
  result.tracking_ms = MsSince(start);
  if (out.new_keyframe) {
    result.new_keyframe = true;
    local_mapping_.InsertKeyFrame(out.new_keyframe, frames_);
  }
  ++frames_;
  // The keyframes merged by this frame (at their hand-off), each once.
  result.mapping_ms = local_mapping_.TakeFinishedMilliseconds();
  return result;
}

Trajectory BackEnd::FrameTrajectory() const {
  std::lock_guard<std::mutex> lock(map_.mutex);
  Trajectory trajectory;
  for (const FrameRecord& r : tracking_.Records()) {
    if (!r.tracked || r.reference == nullptr) continue;
    const Rigid3d cam_from_world = Map::ResolvePose(r.reference, r.cam_from_reference);
    trajectory.push_back({r.timestamp, cam_from_world.inverse()});
  }
  return trajectory;
}

std::vector<std::pair<size_t, double>> BackEnd::DepthScales() const {
  std::lock_guard<std::mutex> lock(map_.mutex);
  std::vector<std::pair<size_t, double>> scales;
  for (const FrameRecord& r : tracking_.Records()) {
    if (r.tracked) scales.emplace_back(r.index, r.depth_scale);
  }
  return scales;
}

Trajectory BackEnd::KeyFrameTrajectory() const {
  std::lock_guard<std::mutex> lock(map_.mutex);
  Trajectory trajectory;
  for (const auto& [id, kf] : map_.KeyFrames()) {
    trajectory.push_back({kf->timestamp, kf->cam_from_world.inverse()});
  }
  return trajectory;
}

std::vector<ColoredPoint> BackEnd::MapPointCloud() const {
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

size_t BackEnd::NumKeyFrames() const {
  std::lock_guard<std::mutex> lock(map_.mutex);
  return map_.NumKeyFrames();
}

size_t BackEnd::NumMapPoints() const {
  std::lock_guard<std::mutex> lock(map_.mutex);
  return map_.NumMapPoints();
}

int BackEnd::NumLost() const { return tracking_.NumLost(); }

int BackEnd::NumTracked() const {
  int n = 0;
  for (const FrameRecord& r : tracking_.Records()) n += r.tracked ? 1 : 0;
  return n;
}

}  // namespace ademono
