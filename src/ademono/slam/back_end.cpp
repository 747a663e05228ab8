#include "ademono/slam/back_end.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <iterator>
#include <sstream>
#include <stdexcept>

#include "ademono/core/error.h"
#include "ademono/core/timing.h"
#include "ademono/slam/map_io.h"

namespace ademono {

BackEnd::BackEnd(const Camera& camera, const SystemOptions& options)
    : camera_(camera),
      options_(options),
      keyframe_database_(options.place),
      local_mapping_(map_, options.mapping, options.tracking.monocular,
                     options.depth.IsPrior() ? options.depth.error_relative : 0.0),
      tracking_(map_, local_mapping_, options) {
  map_.SetKeyFrameDatabase(&keyframe_database_);
  if (options_.loop.enabled) {
    loop_closing_ = std::make_unique<LoopClosing>(
        map_, keyframe_database_, options_.loop,
        options_.loop.UseSim3(options_.depth.IsPrior() || options_.tracking.monocular),
        options_.mapping.fuse_radius);
    local_mapping_.SetLoopClosing(loop_closing_.get());
  }
}

std::vector<LoopEvent> BackEnd::Loops() const {
  MutexLock lock(map_.mutex);
  return loop_closing_ ? loop_closing_->Events() : std::vector<LoopEvent>{};
}

BackEnd::~BackEnd() { Shutdown(); }

void BackEnd::Shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  local_mapping_.Shutdown();
  if (loop_closing_) {
    // A global BA still pending after the last keyframe is merged now (a fixed point too).
    MutexLock lock(map_.mutex);
    loop_closing_->AssertMapHeld();  // the same map, under loop closing's name
    loop_closing_->FinishGlobalBundleAdjustment();
    if (options_.loop.global_ba_at_end && !loaded_map_) loop_closing_->GlobalBundleAdjustmentNow();
  }
}

namespace {

bool SameCamera(const Camera& a, const Camera& b) {
  auto close = [](double x, double y) {
    return std::abs(x - y) <= 1e-6 * std::max(1.0, std::abs(x));
  };
  if (a.width != b.width || a.height != b.height) return false;
  if (!close(a.fx, b.fx) || !close(a.fy, b.fy) || !close(a.cx, b.cx) || !close(a.cy, b.cy))
    return false;
  for (size_t i = 0; i < a.distortion.size(); ++i)
    if (!close(a.distortion[i], b.distortion[i])) return false;
  return true;
}

std::string CameraText(const Camera& c) {
  std::ostringstream o;
  o << c.width << "x" << c.height << " fx " << c.fx << " fy " << c.fy << " cx " << c.cx << " cy "
    << c.cy;
  return o.str();
}

}  // namespace

void BackEnd::LoadMap(const std::filesystem::path& path, bool localize_only,
                      const std::shared_ptr<const ScalePyramid>& pyramid) {
  const MapFileData data = LoadMapFile(path);
  if (!SameCamera(data.camera, camera_)) {
    ThrowInputError(path, "the map's camera (" + CameraText(data.camera) +
                              ") does not match the sequence's (" + CameraText(camera_) + ")");
  }
  MutexLock lock(map_.mutex);
  if (map_.NumKeyFrames() != 0) throw std::logic_error("BackEnd::LoadMap: the map is not empty");
  RestoreMap(data, pyramid, map_, path);
  if (!MapHasMetricScale(data)) scale_free_map_ = path;
  if (localize_only) {
    // Mapping may add temporary keyframes and points beside the loaded ones (tracking's
    // temporary_map) but never changes these; a loop correction would move them, so none.
    for (const auto& [id, kf] : map_.KeyFrames()) kf->frozen = true;
    for (const auto& [id, p] : map_.MapPoints()) p->frozen = true;
    local_mapping_.SetLoopClosing(nullptr);
    loaded_map_ = data;
  }
  tracking_.AssertMapHeld();  // tracking's name for the same lock
  tracking_.StartInLoadedMap(localize_only, scale_free_map_.empty());
}

void BackEnd::SaveMap(const std::filesystem::path& path) {
  Shutdown();
  if (loaded_map_) {
    SaveMapFile(path, *loaded_map_);
    return;
  }
  MapFileData data;
  {
    MutexLock lock(map_.mutex);
    if (loop_closing_ && options_.loop.global_ba_on_save) {
      loop_closing_->AssertMapHeld();  // the same map, under loop closing's name
      loop_closing_->GlobalBundleAdjustmentNow();
    }
    data = MapToRecords(map_, camera_, options_);
  }
  SaveMapFile(path, data);
}

void BackEnd::HandOff() { local_mapping_.HandOff(); }

std::optional<Rigid3d> BackEnd::PredictNext() const {
  MutexLock lock(map_.mutex);
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
  // Sensor depth in metres against a map in other units: every depth residual would pull the
  // pose. Such frames are tracked without their depths until one gives the ratio of the sensor's
  // depths to the map's; the world is then multiplied by it and the depths used from the next
  // frame on. (A network's depth is a prior whose scale each frame measures against the map; the
  // anchor gives the map the network's long-run scale, as it does a new map.)
  const bool measure_scale =
      !scale_free_map_.empty() && !depth.empty() && !options_.depth.IsPrior();
  BackEndResult result;
  const auto start = std::chrono::steady_clock::now();
  TrackingOutput& out = result.tracking;
  {
    MutexLock lock(map_.mutex);
    tracking_.AssertMapHeld();
    out = tracking_.Track(measure_scale ? WithoutDepth(*filtered.features) : filtered.features,
                          frame.index, frame.timestamp, filtered.in_dynamic_box);
    if (measure_scale && out.tracked) {
      if (const std::optional<double> scale = tracking_.SensorToMapScale(*filtered.features)) {
        tracking_.GiveLoadedMapScale(*scale);
        out.cam_from_world.translation() *= *scale;
        spdlog::info("{}: the map had no metric scale; the depth sensor gives it x{:.4f}",
                     scale_free_map_.string(), *scale);
        scale_free_map_.clear();
      }
    }
    // The one rule for map points on moving objects: occlusion-aware, so it needs this frame's
    // depth map; a frame without one culls nothing (it cannot tell a left-behind point from the
    // background the box covers).
    const bool depth_in_map_units = !measure_scale || scale_free_map_.empty();
    if (out.tracked && !depth.empty() && depth_in_map_units &&
        options_.filter.enable_dynamic_removal &&
        !tracking_.LocalizeOnly() && !filtered.moving_detections.empty())
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
  if (out.new_keyframe) {
    result.new_keyframe = true;
    local_mapping_.InsertKeyFrame(out.new_keyframe);
    // Inserting merges the previous keyframe: a loop closed there moved the world under this frame.
    MutexLock lock(map_.mutex);
    tracking_.AssertMapHeld();
    tracking_.FollowLoopCorrection();
    const auto& last = tracking_.LastFrame();
    if (out.tracked && last && last->cam_from_world) out.cam_from_world = *last->cam_from_world;
  }
  // The keyframes merged by this frame (at their hand-off), each once.
  result.mapping_ms = local_mapping_.TakeFinishedMilliseconds();
  return result;
}

Trajectory BackEnd::FrameTrajectory(FramePoses poses, PoseSmoothingReport* smoothing) const {
  Trajectory trajectory;
  {
    MutexLock lock(map_.mutex);
    for (const FrameRecord& r : tracking_.Records()) {
      if (!r.tracked || r.reference == nullptr) continue;
      const Rigid3d cam_from_world = ResolveFramePose(r);
      trajectory.push_back({r.timestamp, cam_from_world.inverse()});
    }
  }
  // Outside the map's lock: local mapping need not wait for it.
  if (poses == FramePoses::kWritten && options_.tracking.smooth_trajectory) {
    std::vector<double> times;
    std::vector<Rigid3d> world_from_cam;
    for (const StampedPose& p : trajectory) {
      times.push_back(p.timestamp);
      world_from_cam.push_back(p.world_from_cam);
    }
    world_from_cam = SmoothPoses(times, world_from_cam, smoothing);
    for (size_t i = 0; i < trajectory.size(); ++i) trajectory[i].world_from_cam = world_from_cam[i];
  }
  return trajectory;
}

std::vector<std::pair<size_t, double>> BackEnd::DepthScales() const {
  MutexLock lock(map_.mutex);
  std::vector<std::pair<size_t, double>> scales;
  for (const FrameRecord& r : tracking_.Records()) {
    if (r.tracked) scales.emplace_back(r.index, r.depth_scale);
  }
  return scales;
}

std::vector<std::pair<size_t, InverseDepthAffine>> BackEnd::NetworkFits() const {
  MutexLock lock(map_.mutex);
  std::vector<std::pair<size_t, InverseDepthAffine>> fits;
  for (const auto& [id, kf] : map_.KeyFrames()) {
    if (kf->network_fit.valid) fits.emplace_back(kf->index, kf->network_fit);
  }
  return fits;
}

Trajectory BackEnd::KeyFrameTrajectory() const {
  MutexLock lock(map_.mutex);
  Trajectory trajectory;
  for (const auto& [id, kf] : map_.KeyFrames()) {
    trajectory.push_back({kf->timestamp, kf->cam_from_world.inverse()});
  }
  return trajectory;
}

std::vector<ColoredPoint> BackEnd::MapPointCloud() const {
  MutexLock lock(map_.mutex);
  std::vector<ColoredPoint> cloud;
  for (const auto& [id, p] : map_.MapPoints()) {
    if (p->bad) continue;
    auto it = point_colors_.find(id);
    cloud.push_back(
        {p->position, it == point_colors_.end() ? cv::Vec3b(255, 255, 255) : it->second,
         p->static_probability});
  }
  return cloud;
}

MapFileData BackEnd::MapRecords() const {
  MutexLock lock(map_.mutex);
  return MapToRecords(map_, camera_, options_);
}

size_t BackEnd::NumKeyFrames() const {
  MutexLock lock(map_.mutex);
  return map_.NumKeyFrames();
}

size_t BackEnd::NumMapPoints() const {
  MutexLock lock(map_.mutex);
  return map_.NumMapPoints();
}

int BackEnd::NumLost() const { return tracking_.NumLost(); }

std::vector<double> BackEnd::GroundHeights() const {
  MutexLock lock(map_.mutex);
  return tracking_.GroundHeights();
}

std::vector<size_t> BackEnd::GroundHeightFrames() const {
  MutexLock lock(map_.mutex);
  return tracking_.GroundHeightFrames();
}

int BackEnd::NumTracked() const {
  int n = 0;
  for (const FrameRecord& r : tracking_.Records()) n += r.tracked ? 1 : 0;
  return n;
}

}  // namespace ademono
