#pragma once
// The back end of the SLAM system: a front end's filtered frame meets the map. Tracking (pose,
// keyframe decision), culling of map points on moving objects, and local mapping; it owns the
// map and answers every question about it (trajectories, point cloud, counts).

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ademono/core/camera.h"
#include "ademono/io/sequence.h"
#include "ademono/io/trajectory.h"
#include "ademono/optimize/trajectory_smoothing.h"
#include "ademono/perception/detection.h"
#include "ademono/place/keyframe_database.h"
#include "ademono/slam/front_end.h"
#include "ademono/slam/local_mapping.h"
#include "ademono/slam/loop_closing.h"
#include "ademono/slam/map.h"
#include "ademono/slam/map_io.h"
#include "ademono/slam/options.h"
#include "ademono/slam/tracking.h"

namespace ademono {

// Which frame poses a trajectory holds (BackEnd::FrameTrajectory).
enum class FramePoses { kWritten, kResolved };

struct ColoredPoint {
  Eigen::Vector3d position;
  cv::Vec3b bgr;
  double static_probability = 1.0;  // MapPoint::static_probability (the live view's colour)
};

// The back end's part of one frame's result.
struct BackEndResult {
  TrackingOutput tracking;
  TrackingState state = TrackingState::kNotInitialized;
  bool new_keyframe = false;
  double tracking_ms = 0;  // tracking and culling, map lock held
  double mapping_ms = 0;   // local mapping of the keyframes finished by this frame
};

class BackEnd {
 public:
  BackEnd(const Camera& camera, const SystemOptions& options);
  ~BackEnd();
  BackEnd(const BackEnd&) = delete;
  BackEnd& operator=(const BackEnd&) = delete;

  // Start of a frame's back end, before PredictNext and Track: merges local mapping's pending
  // keyframe when this frame is its hand-off frame (the fixed schedule, slam/local_mapping.h).
  // Local mapping counts the frames (these calls), not their input index, which may repeat or
  // jump.
  void HandOff();
  // Constant-velocity prediction of the next frame's pose (the dynamic filter's stage 2).
  std::optional<Rigid3d> PredictNext() const;
  // `frame`: its index, timestamp and image (map point colours); `depth` as System::TrackFrame.
  BackEndResult Track(const FrameData& frame, const cv::Mat& depth, const FilteredFrame& filtered);
  // Finishes local mapping. Idempotent.
  void Shutdown();

  // Map reuse (docs/maps.md). LoadMap: before the first frame; restores a saved map (InputError
  // naming the file for a bad map or a camera that differs from this system's), then the first
  // frames relocalise in it. With `localize_only` the map is never changed (its keyframes and
  // points are frozen; tracking.temporary_map may add temporary ones beside them, which are never
  // saved) and no loop is closed. SaveMap finishes local mapping (Shutdown) and writes the map
  // atomically (after localisation only: the loaded map as it was read).
  // A map without metric scale (--depth none without a camera height: MapScaleOf) is tracked
  // without depth; with a network's depth (a prior) the anchor gives it the network's long-run
  // scale, as it does a new map; with sensor depth its frames are tracked without their depths
  // until one measures the sensor's depths against the map, and the world is multiplied by that.
  void LoadMap(const std::filesystem::path& path, bool localize_only,
               const std::shared_ptr<const ScalePyramid>& pyramid);
  // False after LoadMap of a map without metric scale, until a depth sensor gave it one; true
  // otherwise.
  bool LoadedMapHasMetricScale() const { return scale_free_map_.empty(); }
  void SaveMap(const std::filesystem::path& path);
  // Place recognition index of the live keyframes (thread-safe on its own).
  const KeyFrameDatabase& GetKeyFrameDatabase() const { return keyframe_database_; }
  // Loops closed so far (loop closing, docs/loops.md).
  std::vector<LoopEvent> Loops() const;

  // kWritten: as the run writes it (smoothed where tracking.smooth_trajectory says so);
  // kResolved: against the keyframes only (cheaper, for the live view's periodic snapshots).
  Trajectory FrameTrajectory(FramePoses poses = FramePoses::kWritten,
                             PoseSmoothingReport* smoothing = nullptr) const;
  Trajectory KeyFrameTrajectory() const;
  std::vector<std::pair<size_t, double>> DepthScales() const;
  // Monocular core with a network: each live keyframe's fitted network error model (input
  // frame index, fit), in keyframe order; keyframes without a valid fit are left out.
  std::vector<std::pair<size_t, InverseDepthAffine>> NetworkFits() const;
  std::vector<ColoredPoint> MapPointCloud() const;
  MapFileData MapRecords() const;
  size_t NumKeyFrames() const;
  size_t NumMapPoints() const;
  int NumLost() const;
  // depth.camera_height: the camera heights measured above the ground (Tracking::GroundHeights).
  std::vector<double> GroundHeights() const;
  std::vector<size_t> GroundHeightFrames() const;  // Tracking::GroundHeightFrames
  int NumTracked() const;

 private:
  // Counts hits of map points landing on moving objects (map_.mutex held) and erases those with
  // tracking.dynamic_cull_hits of them; returns how many were erased.
  int CullPointsOnMovingObjects(const Rigid3d& cam_from_world, const cv::Mat& depth,
                                const std::vector<Detection>& moving_boxes)
      ADEMONO_REQUIRES(map_.mutex);

  Camera camera_;
  SystemOptions options_;
  // Place recognition over the live keyframes (the map adds and erases them); declared before
  // the map so it outlives the map's pointer to it.
  KeyFrameDatabase keyframe_database_;
  mutable Map map_;  // mutable: const accessors lock its mutex
  // Null when loop.enabled is false; declared before local mapping, which calls it until shutdown.
  std::unique_ptr<LoopClosing> loop_closing_;
  LocalMapping local_mapping_;
  Tracking tracking_;
  // Colour of each map point's first observation (for map.ply), keyed by point id.
  std::map<uint64_t, cv::Vec3b> point_colors_;
  // Localisation only: the map as loaded, what SaveMap writes (temporary keyframes never are).
  std::optional<MapFileData> loaded_map_;
  // The loaded map's file when it has no metric scale (empty otherwise).
  std::filesystem::path scale_free_map_;
  bool shut_down_ = false;
};

}  // namespace ademono
