#pragma once
// The SLAM facade: one call per input frame. The front end (slam/front_end) extracts ORB
// features, reads each keypoint's depth from the frame's metric depth map and applies the
// method's filters (enhancement, dynamic removal, distant filter); the back end (slam/back_end)
// tracks the kept features against the map, culls points on moving objects and maps.

#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "ademono/core/camera.h"
#include "ademono/filter/feature_filter.h"
#include "ademono/io/sequence.h"
#include "ademono/io/trajectory.h"
#include "ademono/perception/detection.h"
#include "ademono/slam/back_end.h"
#include "ademono/slam/front_end.h"
#include "ademono/slam/options.h"
#include "ademono/slam/tracking.h"

namespace ademono {

// Per-frame result, with the time spent in each stage.
struct TrackResult {
  size_t index = 0;
  bool tracked = false;
  std::optional<Rigid3d> cam_from_world;
  TrackingState state = TrackingState::kNotInitialized;
  bool relocalised = false;  // tracked again by relocalisation after being lost
  bool new_keyframe = false;
  int num_keypoints = 0;   // extracted
  int num_kept = 0;        // after the filters
  int num_with_depth = 0;  // kept keypoints with valid depth
  int inliers = 0;
  int dynamic_points_culled = 0;  // map points culled for sitting in dynamic boxes
  PoseQuality quality = PoseQuality::kGood;  // tracked frames: what the pose rests on
  int geometric_dynamic = 0;  // matched map points the geometric test judged moving
  int geometric_culled = 0;   // map points it culled
  double depth_scale = 1.0;       // network depth: this frame's scale correction
  // Network depth or a ground scale: the relative standard error of the run's metric scale as
  // this frame leaves it (Tracking::ScaleSigma); none for sensor depth and `--depth none`.
  std::optional<double> scale_sigma;
  FilterStats filter_stats;
  std::vector<cv::KeyPoint> keypoints;  // all extracted keypoints ...
  std::vector<PointLabel> labels;       // ... and their filter labels (for --viz)
  // ... and per keypoint what tracking made of it (kUnmatched for keypoints the filter removed;
  // empty when the frame is untracked).
  std::vector<MatchState> match_state;
  // ... and the map points a new keyframe made from them (index into `keypoints`; see
  // TrackingOutput::created_points).
  std::vector<std::pair<size_t, std::shared_ptr<const MapPoint>>> created_points;
  // Wall milliseconds per stage. extraction (grey + ORB) and keypoint_depth come from wherever
  // the frame was extracted (the pipeline's prefetch thread, or TrackFrame itself).
  double extraction_ms = 0, keypoint_depth_ms = 0, filter_ms = 0, tracking_ms = 0, mapping_ms = 0;
};

class System {
 public:
  System(const Camera& camera, const SystemOptions& options);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  // `depth`: CV_32FC1 metres at the image's size (0 = invalid) or empty (no depth for this
  // frame: tracked with 2-dof residuals only). `image` may be CV_8UC1 or CV_8UC3.
  TrackResult TrackFrame(const FrameData& frame, const cv::Mat& depth,
                         const std::vector<Detection>& detections);
  // The same with the frame already extracted by ExtractFrame (byte-identical results: extraction
  // is a pure function of the image and the depth map).
  TrackResult TrackFrame(const FrameData& frame, const cv::Mat& depth,
                         const std::vector<Detection>& detections, ExtractedFrame extracted);
  // ORB extraction and keypoint depths of a frame, no system state: thread-safe, may run on
  // another thread while earlier frames are tracked. ExtractFeatures + AddDepths split it so the
  // features can be extracted while the depth map is still being computed.
  ExtractedFrame ExtractFrame(const FrameData& frame, const cv::Mat& depth) const {
    return front_end_.Extract(frame, depth);
  }
  ExtractedFrame ExtractFeatures(const FrameData& frame) const {
    return front_end_.ExtractFeatures(frame);
  }
  void AddDepths(ExtractedFrame& extracted, const cv::Mat& depth) const {
    front_end_.AddDepths(extracted, depth);
  }
  // Finishes local mapping (threaded mode). Idempotent.
  void Shutdown();

  // Map reuse (docs/maps.md), see BackEnd::LoadMap and BackEnd::SaveMap.
  void LoadMap(const std::filesystem::path& path, bool localize_only) {
    back_end_.LoadMap(path, localize_only, front_end_.Pyramid());
  }
  void SaveMap(const std::filesystem::path& path) { back_end_.SaveMap(path); }
  // False after loading a map built with --depth none (BackEnd::LoadMap).
  bool LoadedMapHasMetricScale() const { return back_end_.LoadedMapHasMetricScale(); }

  // Pose of every tracked input frame, resolved against the current keyframe poses (and, as
  // written, smoothed where tracking.smooth_trajectory is on).
  Trajectory FrameTrajectory(FramePoses poses = FramePoses::kWritten,
                             PoseSmoothingReport* smoothing = nullptr) const;
  Trajectory KeyFrameTrajectory() const;
  // Network depth: the scale correction of every tracked frame (input index, factor), against
  // the final map (anchoring rescales update it); 1 for sensor depth.
  std::vector<std::pair<size_t, double>> DepthScales() const;
  // Monocular core with a network: the network error model fitted in each keyframe
  // (BackEnd::NetworkFits).
  std::vector<std::pair<size_t, InverseDepthAffine>> NetworkFits() const {
    return back_end_.NetworkFits();
  }
  using ColoredPoint = ademono::ColoredPoint;
  std::vector<ColoredPoint> MapPointCloud() const;
  // The live map as the records a map file holds (temporary keyframes included; tests).
  MapFileData MapRecords() const { return back_end_.MapRecords(); }
  size_t NumKeyFrames() const;
  size_t NumMapPoints() const;
  int NumLost() const;
  // depth.camera_height: the camera heights above the ground plane measured so far, in the
  // map's units (Tracking::GroundHeights).
  std::vector<double> GroundHeights() const;
  // The input frame index of each GroundHeights() entry (a keyframe's, or the first frame's).
  std::vector<size_t> GroundHeightFrames() const { return back_end_.GroundHeightFrames(); }
  int NumTracked() const;
  const Camera& GetCamera() const { return camera_; }
  const SystemOptions& Options() const { return options_; }
  // Place recognition index of the live keyframes (thread-safe on its own).
  const KeyFrameDatabase& GetKeyFrameDatabase() const { return back_end_.GetKeyFrameDatabase(); }
  // Loops closed so far (loop closing, docs/loops.md).
  std::vector<LoopEvent> Loops() const { return back_end_.Loops(); }

  // Per-keypoint depth from the depth map: nearest pixel, range and discontinuity checks.
  static std::vector<float> KeypointDepths(const std::vector<cv::KeyPoint>& keypoints,
                                           const cv::Mat& depth, const FrameDepthOptions& options) {
    return FrontEnd::KeypointDepths(keypoints, depth, options);
  }

 private:
  Camera camera_;
  SystemOptions options_;
  FrontEnd front_end_;
  BackEnd back_end_;
};

}  // namespace ademono
