#pragma once
// Descriptor matching for tracking and mapping (after ORB-SLAM's ORBmatcher): search by
// projection with a window radius by scale level (and viewing angle), Hamming thresholds, a
// ratio test between the two best candidates and rotation consistency (a 30-bin histogram of
// keypoint angle differences; only the three fullest bins are kept). The thresholds and the
// histogram are the feature module's (feature/matching.h).

#include <memory>
#include <vector>

#include "ademono/feature/matching.h"
#include "ademono/slam/frame.h"
#include "ademono/slam/keyframe.h"
#include "ademono/slam/map.h"

namespace ademono {

class WorkerPool;  // core/worker_pool.h

class Matcher {
 public:
  Matcher(float nn_ratio, bool check_orientation)
      : nn_ratio_(nn_ratio), check_orientation_(check_orientation) {}

  // Constant-velocity tracking: map points of `last` projected into `current` (whose pose is
  // the prediction). Returns the number of new matches written into current.map_points.
  int SearchByProjection(Frame& current, const Frame& last, float radius) const;

  // Local-map tracking: `points` with their predictions (from Frame::InFrustum).
  int SearchByProjection(Frame& frame, const std::vector<std::shared_ptr<MapPoint>>& points,
                         const std::vector<ProjectionPrediction>& predictions, float radius) const;

  // The keypoint of `frame` that best matches `point` within `radius` (px at the predicted level)
  // of its prediction, on the predicted level or the one below, passing the distance threshold
  // and the ratio test; -1 if none. Keypoints already matched are candidates too; nothing is
  // written (the geometric test judges a new point in the frame before its keyframe).
  int FindByProjection(const Frame& frame, const MapPoint& point,
                       const ProjectionPrediction& prediction, float radius) const;

  // Relocalisation: map points of `keyframe` not yet in `found` projected into `frame`.
  int SearchByProjection(Frame& frame, const KeyFrame& keyframe, float radius,
                         int max_distance) const;

  // Descriptor matching (brute force, ratio test, rotation check) of the frame's keypoints
  // against the keyframe's keypoints that have map points: writes the matches into `matches`
  // (one map point or null per frame keypoint). Used when the motion model fails and to
  // relocalise. Returns the number of matches.
  int SearchByDescriptor(const KeyFrame& keyframe, const Frame& frame,
                         std::vector<std::shared_ptr<MapPoint>>& matches) const;

  // Fusion: projects `points` into `keyframe`; a point matching a keypoint that already has a
  // map point is merged with it (the one with fewer observations is replaced), otherwise it gets
  // the new observation. Returns the number of fused points.
  int Fuse(Map& map, KeyFrame& keyframe, const std::vector<std::shared_ptr<MapPoint>>& points,
           float radius) const ADEMONO_REQUIRES(map.mutex);

  // Triangulation (ORB-SLAM's SearchForTriangulation without a vocabulary): keypoints of `k1` and
  // `k2` that have no map point yet, matched by descriptor (best below kOrbDistanceLow, ratio test,
  // rotation check) among the candidates within the epipolar band of k2 (chi2 3.84 at the
  // candidate's level). A k1 keypoint with a depth prior only searches the part of its epipolar
  // line within `depth_sigmas` sigma of that depth (the whole line without one). Appends
  // (k1 index, k2 index) pairs, each k2 keypoint at most once, and returns their number. With a
  // `helper`, its thread scans the second half of k1's keypoints while the caller scans the first;
  // the matches are the same as without one, to the bit.
  int SearchForTriangulation(const KeyFrame& k1, const KeyFrame& k2, double depth_sigmas,
                             std::vector<std::pair<size_t, size_t>>& matches,
                             WorkerPool* helper = nullptr) const;

  // Monocular initialisation (ORB-SLAM's SearchForInitialization): every keypoint of `f1` is
  // matched with the best keypoint of `f2` on the same pyramid level within `window` px (level 0)
  // of `prev_matched[i]`, its position in the last frame that matched it (f1's own position at
  // first): Hamming distance at most kOrbDistanceLow, ratio test, each f2 keypoint kept for its
  // best f1 keypoint only, rotation consistency. `matches12[i]` is the f2 index or -1; matched
  // positions replace `prev_matched`. Returns the number of matches.
  int SearchForInitialization(const FrameFeatures& f1, const FrameFeatures& f2,
                              std::vector<cv::Point2f>& prev_matched, std::vector<int>& matches12,
                              float window) const;

  static float RadiusByViewingCos(float view_cos) { return view_cos > 0.998f ? 2.5f : 4.0f; }

 private:
  float nn_ratio_;
  bool check_orientation_;
};

}  // namespace ademono
