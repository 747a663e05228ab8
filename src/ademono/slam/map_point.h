#pragma once
// A 3D landmark with its observations in keyframes (ORB-SLAM's MapPoint). All mutable state is
// guarded by the owning Map's mutex (see map.h).

#include <Eigen/Core>
#include <boost/container/flat_map.hpp>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>

namespace ademono {

class KeyFrame;

// Orders keyframes by id so every container iterated for optimisation is deterministic.
struct KeyFrameIdLess {
  bool operator()(const KeyFrame* a, const KeyFrame* b) const;
};

class MapPoint {
 public:
  MapPoint(uint64_t id, const Eigen::Vector3d& position, KeyFrame* reference,
           uint64_t first_frame_id);

  const uint64_t id;
  Eigen::Vector3d position;
  cv::Mat descriptor;  // the most distinctive of the observations' descriptors
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // mean viewing direction
  float min_distance = 0, max_distance = 0;          // scale invariance range
  KeyFrame* reference = nullptr;
  uint64_t first_keyframe_id = 0;
  uint64_t first_frame_id = 0;
  // keyframe -> keypoint index, in keyframe order. A sorted vector: tracking's local map and every
  // local BA walk these thousands of times a keyframe, and a tree's node-to-node walk was 4 % of
  // a monocular run's CPU. Inserting or erasing invalidates iterators: copy before changing it
  // inside a walk over it (Map::ErasePoint and ReplacePoint do).
  boost::container::flat_map<KeyFrame*, size_t, KeyFrameIdLess> observations;
  int visible = 1;  // frames in whose frustum the point was
  int found = 1;    // frames that matched it as an inlier
  int dynamic_hits = 0;
  // P(static) of the geometric test (slam/static_probability.h); 1 when the test is off.
  double static_probability = 1.0;
  // Whether the point was ever let into the pose and local BA (P(static) at or above the
  // geometric test's threshold). A new keyframe's point starts below it and is admitted only
  // when another view confirms it; until then local BA leaves it out, as the pose does. A mover's
  // point is never admitted (synthetic truth scores this).
  bool admitted = true;
  // Monocular core with a network: the point was placed by its reference keyframe's network
  // depth, which local BA keeps as a prior on that observation while geometry cannot place it
  // (its parallax gives a depth less certain than the network's; LocalMapping).
  bool depth_prior = false;
  int motion_verdicts = 0;  // the geometric test's verdicts of motion (synthetic truth scores it)
  bool bad = false;
  // Part of a map loaded for localisation only: position, descriptor, normal, statistics and its
  // observations by loaded keyframes never change (temporary keyframes may observe it).
  bool frozen = false;
  std::shared_ptr<MapPoint> replaced_by;

  // Per-frame scratch of the tracker (which frame last used the point, to avoid duplicates).
  uint64_t last_frame_seen = UINT64_MAX;
  uint64_t local_map_frame = UINT64_MAX;
  uint64_t fuse_target_keyframe = UINT64_MAX;
  uint64_t ba_local_for = UINT64_MAX;

  int NumObservations() const { return static_cast<int>(observations.size()); }
  bool IsInKeyFrame(const KeyFrame* keyframe) const {
    return observations.count(const_cast<KeyFrame*>(keyframe)) > 0;
  }
  float FoundRatio() const { return static_cast<float>(found) / static_cast<float>(visible); }
  void AddObservation(KeyFrame* keyframe, size_t index);
  void EraseObservation(KeyFrame* keyframe);  // the point turns bad when it falls below 1 view
  void ComputeDistinctiveDescriptor();
  void UpdateNormalAndDepth();
  // Pyramid level at which a keypoint of this point is expected at `distance`.
  int PredictScale(float distance, float log_scale_factor, int num_levels) const;
  // The point itself or whatever replaced it (following the chain).
  static std::shared_ptr<MapPoint> Resolve(std::shared_ptr<MapPoint> point);
};

}  // namespace ademono
