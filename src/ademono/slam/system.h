#pragma once
// The SLAM facade: one call per input frame. Extracts ORB features, reads each keypoint's depth
// from the frame's metric depth map, applies the method's filters (enhancement, dynamic removal,
// distant filter) and tracks the kept features; local mapping runs synchronously (deterministic)
// or in its own thread.

#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "ademono/core/camera.h"
#include "ademono/feature/orb_extractor.h"
#include "ademono/filter/feature_filter.h"
#include "ademono/io/sequence.h"
#include "ademono/io/trajectory.h"
#include "ademono/perception/detection.h"
#include "ademono/slam/local_mapping.h"
#include "ademono/slam/map.h"
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
  FilterStats filter_stats;
  std::vector<cv::KeyPoint> keypoints;  // all extracted keypoints ...
  std::vector<PointLabel> labels;       // ... and their filter labels (for --viz)
  double extraction_ms = 0, filter_ms = 0, tracking_ms = 0, mapping_ms = 0;
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
  // Finishes local mapping (threaded mode). Idempotent.
  void Shutdown();

  // Pose of every tracked input frame, resolved against the current keyframe poses.
  Trajectory FrameTrajectory() const;
  Trajectory KeyFrameTrajectory() const;
  // Network depth: the scale correction of every tracked frame (input index, factor), against
  // the final map (anchoring rescales update it); 1 for sensor depth.
  std::vector<std::pair<size_t, double>> DepthScales() const;
  struct ColoredPoint {
    Eigen::Vector3d position;
    cv::Vec3b bgr;
  };
  std::vector<ColoredPoint> MapPointCloud() const;
  size_t NumKeyFrames() const;
  size_t NumMapPoints() const;
  int NumLost() const;
  int NumTracked() const;
  const Camera& GetCamera() const { return camera_; }
  const SystemOptions& Options() const { return options_; }

  // Per-keypoint depth from the depth map: nearest pixel, range and discontinuity checks.
  static std::vector<float> KeypointDepths(const std::vector<cv::KeyPoint>& keypoints,
                                           const cv::Mat& depth, const FrameDepthOptions& options);

 private:
  // Counts hits of map points landing on moving objects (map_.mutex held) and erases those with
  // tracking.dynamic_cull_hits of them; returns how many were erased.
  int CullPointsOnMovingObjects(const Rigid3d& cam_from_world, const cv::Mat& depth,
                                 const std::vector<Detection>& moving_boxes);

  Camera camera_;
  SystemOptions options_;
  OrbExtractor extractor_;
  std::shared_ptr<const ScalePyramid> pyramid_;
  FeatureFilter filter_;
  mutable Map map_;  // mutable: const accessors lock its mutex
  LocalMapping local_mapping_;
  Tracking tracking_;
  std::optional<PreviousFrameFeatures> previous_;
  // Colour of each map point's first observation (for map.ply), keyed by point id.
  std::map<uint64_t, cv::Vec3b> point_colors_;
  bool shut_down_ = false;
};

}  // namespace ademono
