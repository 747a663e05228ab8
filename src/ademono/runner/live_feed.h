#pragma once
// What a run shows while it runs, without any networking: a RunObserver receives copies of each
// frame's result and of the map on the tracking thread, and must return at once (the live view,
// src/ademono/live, queues them for its own thread). LiveFeed builds those copies from a System
// and its TrackResults for RunSequence and for the Python System. Nothing here changes the run:
// the observer only reads, through the System's const accessors, on the thread that owns the map
// between two frames.

#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "ademono/filter/feature_filter.h"
#include "ademono/io/sequence.h"
#include "ademono/io/trajectory.h"
#include "ademono/perception/detection.h"
#include "ademono/slam/system.h"

namespace ademono {

// One frame as the live view shows it.
struct LiveFrame {
  size_t frame = 0;  // the sequence's frame index
  double timestamp = 0;
  bool tracked = false, keyframe = false, relocalised = false;
  TrackingState state = TrackingState::kNotInitialized;
  PoseQuality quality = PoseQuality::kGood;
  std::optional<Rigid3d> cam_from_world;
  int keypoints = 0, kept = 0, with_depth = 0, inliers = 0;
  std::optional<double> depth_scale;  // network depth (or a ground scale): this frame's factor
  std::optional<double> scale_sigma;  // ... and the metric scale's relative standard error
  // Wall milliseconds of the stages the frame's TrackResult measured.
  double extraction_ms = 0, keypoint_depth_ms = 0, filter_ms = 0, tracking_ms = 0, mapping_ms = 0;
  std::vector<cv::Point2f> points;  // every extracted keypoint ...
  std::vector<PointLabel> labels;   // ... and its filter label
  std::vector<Detection> detections;
  int image_width = 0, image_height = 0;
  cv::Mat image;  // a copy of the input image when the observer wants images, else empty
};

struct LiveMapPoint {
  Eigen::Vector3f position;
  float static_probability = 1;
};

// The map and what rests on it, at one frame (or at the end of the run: `final`).
struct LiveMap {
  size_t frame = 0;
  double timestamp = 0;
  bool final = false;
  std::vector<LiveMapPoint> points;
  Trajectory trajectory;  // every tracked frame so far, against the current keyframe poses
  Trajectory keyframes;
  // Closed loops as (query, match) camera positions in the current map.
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> loops;
};

struct LiveEnd {
  size_t frames = 0, tracked = 0, keyframes = 0, map_points = 0;
  int lost = 0;
  bool partial = false;  // stopped early (Ctrl-C)
};

class RunObserver {
 public:
  virtual ~RunObserver() = default;
  // Asked before each copy, so that a run without viewers copies nothing.
  virtual bool WantsFrames() const = 0;
  virtual bool WantsImages() const = 0;
  // Whether to take a map snapshot now: `map_changed` since the last one it took.
  virtual bool WantsMapSnapshot(bool map_changed) = 0;
  // Called on the tracking thread; must not block.
  virtual void OnFrame(LiveFrame frame) = 0;
  virtual void OnMap(LiveMap map) = 0;
  // After the last frame and the last mapping step: the map as map.ply, the trajectory as
  // trajectory.tum.
  virtual void OnEnd(LiveMap final_map, const LiveEnd& end) = 0;
};

class LiveFeed {
 public:
  explicit LiveFeed(RunObserver* observer) : observer_(observer) {}
  // After System::TrackFrame of `frame`. The map is sent when it changed: at a new keyframe, at a
  // local mapping merge, at a loop.
  void Frame(const System& system, const FrameData& frame, const std::vector<Detection>& detections,
             const TrackResult& r);
  // After System::Shutdown.
  void End(const System& system, const LiveEnd& end);

 private:
  LiveMap Snapshot(const System& system, size_t frame, double timestamp, FramePoses poses) const;
  RunObserver* observer_;
  size_t loops_seen_ = 0;
  bool map_stale_ = false;  // changed since the last snapshot
  std::map<size_t, double> timestamps_;  // frame index -> timestamp (loop ends)
};

}  // namespace ademono
