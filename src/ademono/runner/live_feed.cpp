#include "ademono/runner/live_feed.h"

#include <algorithm>

namespace ademono {
namespace {

// Camera centre of frame `index` in `trajectory`, found by its timestamp.
std::optional<Eigen::Vector3d> PositionAt(const Trajectory& trajectory,
                                          const std::map<size_t, double>& timestamps,
                                          size_t index) {
  const auto t = timestamps.find(index);
  if (t == timestamps.end()) return std::nullopt;
  const auto it = std::lower_bound(
      trajectory.begin(), trajectory.end(), t->second,
      [](const StampedPose& p, double stamp) { return p.timestamp < stamp; });
  if (it == trajectory.end() || it->timestamp != t->second) return std::nullopt;
  return it->world_from_cam.translation();
}

}  // namespace

LiveMap LiveFeed::Snapshot(const System& system, size_t frame, double timestamp,
                           FramePoses poses) const {
  LiveMap map;
  map.frame = frame;
  map.timestamp = timestamp;
  const std::vector<ColoredPoint> cloud = system.MapPointCloud();
  map.points.reserve(cloud.size());
  for (const ColoredPoint& p : cloud)
    map.points.push_back({p.position.cast<float>(), static_cast<float>(p.static_probability)});
  map.trajectory = system.FrameTrajectory(poses);
  map.keyframes = system.KeyFrameTrajectory();
  for (const LoopEvent& loop : system.Loops()) {
    const auto a = PositionAt(map.trajectory, timestamps_, loop.query_frame);
    const auto b = PositionAt(map.trajectory, timestamps_, loop.match_frame);
    if (a && b) map.loops.emplace_back(*a, *b);
  }
  return map;
}

void LiveFeed::Frame(const System& system, const FrameData& frame,
                     const std::vector<Detection>& detections, const TrackResult& r) {
  if (observer_ == nullptr) return;
  timestamps_[frame.index] = frame.timestamp;
  if (observer_->WantsFrames()) {
    LiveFrame f;
    f.frame = frame.index;
    f.timestamp = frame.timestamp;
    f.tracked = r.tracked;
    f.keyframe = r.new_keyframe;
    f.relocalised = r.relocalised;
    f.state = r.state;
    f.quality = r.quality;
    f.cam_from_world = r.cam_from_world;
    f.keypoints = r.num_keypoints;
    f.kept = r.num_kept;
    f.with_depth = r.num_with_depth;
    f.inliers = r.inliers;
    const FrameDepthOptions& depth = system.Options().depth;
    if (r.tracked && (depth.IsPrior() || depth.GroundScale())) f.depth_scale = r.depth_scale;
    f.scale_sigma = r.scale_sigma;
    f.extraction_ms = r.extraction_ms;
    f.keypoint_depth_ms = r.keypoint_depth_ms;
    f.filter_ms = r.filter_ms;
    f.tracking_ms = r.tracking_ms;
    f.mapping_ms = r.mapping_ms;
    f.points.reserve(r.keypoints.size());
    for (const cv::KeyPoint& k : r.keypoints) f.points.push_back(k.pt);
    f.labels = r.labels;
    f.detections = detections;
    f.image_width = frame.image.cols;
    f.image_height = frame.image.rows;
    if (observer_->WantsImages()) f.image = frame.image.clone();
    observer_->OnFrame(std::move(f));
  }
  const std::vector<LoopEvent> loops = system.Loops();
  map_stale_ = map_stale_ || r.new_keyframe || r.mapping_ms > 0 || loops.size() != loops_seen_;
  loops_seen_ = loops.size();
  if (observer_->WantsMapSnapshot(map_stale_)) {
    map_stale_ = false;
    // The path as resolved: smoothing the whole run at every snapshot would cost the tracking
    // thread ~4 ms per 1,000 frames (bench_trajectory_smoothing); the final snapshot has it.
    observer_->OnMap(Snapshot(system, frame.index, frame.timestamp, FramePoses::kResolved));
  }
}

void LiveFeed::End(const System& system, const LiveEnd& end) {
  if (observer_ == nullptr) return;
  const double timestamp = timestamps_.empty() ? 0.0 : timestamps_.rbegin()->second;
  const size_t frame = timestamps_.empty() ? 0 : timestamps_.rbegin()->first;
  LiveMap map = Snapshot(system, frame, timestamp, FramePoses::kWritten);
  map.final = true;
  observer_->OnEnd(std::move(map), end);
}

}  // namespace ademono
