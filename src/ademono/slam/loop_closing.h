#pragma once
// Loop closing (ORB-SLAM's LoopClosing, run synchronously after each keyframe's local mapping so
// deterministic mode stays deterministic). For a new keyframe:
//  1. detection: the place-recognition index (place/keyframe_database.h) proposes keyframes that
//     look alike, excluding the keyframe's covisible and most recent keyframes;
//  2. verification: descriptor matches between the two keyframes' map points, a 3D-3D RANSAC of
//     3-point Umeyama fits (Sim(3) when depth is a network's prior, whose scale drifts; SE(3)
//     with sensor depth) scored by reprojection in both images, then a guided projection search
//     of the candidate's neighbourhood into the keyframe;
//  3. consistency: the same place (a candidate or its covisible keyframes) verified for
//     `consistency` consecutive keyframes;
//  4. correction: the keyframe and its covisible keyframes are moved by the loop transform, their
//     points follow, duplicated points across the loop are fused, covisibility is updated and the
//     essential graph (spanning tree, strong covisibility edges, loop edges) is optimised with
//     Ceres; every other point follows its reference keyframe.
//  5. optional global bundle adjustment (loop.global_ba): every live keyframe and point is
//     gathered right after the correction and solved on a thread of its own from that snapshot
//     while tracking and local mapping go on; the result is merged when loop closing has seen
//     loop.global_ba_handoff_keyframes more keyframes (or at shutdown), a fixed point in the
//     sequence, so runs stay deterministic. Keyframes and points made since the snapshot follow
//     the correction of their spanning-tree ancestor / reference keyframe (ORB-SLAM's
//     RunGlobalBundleAdjustment). A new loop before the hand-off discards the pending solve.
// Every call runs with the map mutex held.

#include <cstdint>
#include <exception>
#include <memory>
#include <thread>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "ademono/optimize/bundle_adjustment.h"
#include "ademono/optimize/pose_graph.h"
#include "ademono/place/keyframe_database.h"
#include "ademono/slam/map.h"
#include "ademono/slam/options.h"

namespace ademono {

// One closed loop (summary.json's `loops`).
struct LoopEvent {
  uint64_t query_keyframe = 0, match_keyframe = 0;
  size_t query_frame = 0, match_frame = 0;  // input frame indices
  double query_timestamp = 0;
  int inliers = 0;  // 3D-3D RANSAC inliers
  int matches = 0;  // after the projection search
  double scale = 1;  // loop transform's scale (1 with SE(3))
  bool sim3 = false;
  // How far the query keyframe moved: camera centre (metres) and rotation (degrees).
  double correction_m = 0, correction_deg = 0;
  int fused_points = 0;
  size_t graph_keyframes = 0, graph_edges = 0;
  double milliseconds = 0;  // verification of the accepted candidate + correction
  // Global BA after this loop (loop.global_ba): problem size, solve time on its thread, the
  // keyframe at whose processing it was merged; merged false when it was not (a newer loop
  // came first).
  bool global_ba = false, global_ba_merged = false;
  size_t global_ba_keyframes = 0, global_ba_points = 0;
  uint64_t global_ba_merged_at_keyframe = 0;
  double global_ba_ms = 0;
};

class LoopClosing {
 public:
  LoopClosing(Map& map, const KeyFrameDatabase& database, const LoopOptions& options, bool sim3,
              double fuse_radius);
  ~LoopClosing();  // waits for a global BA still solving (its result is dropped)
  LoopClosing(const LoopClosing&) = delete;
  LoopClosing& operator=(const LoopClosing&) = delete;

  // Detects, verifies and corrects a loop for `keyframe`; true when a loop was closed.
  bool Process(KeyFrame& keyframe) ADEMONO_REQUIRES(map_.mutex);
  const std::vector<LoopEvent>& Events() const { return events_; }
  bool UsesSim3() const { return sim3_; }
  // End of the sequence: merges a pending global BA (waits for its solve).
  void FinishGlobalBundleAdjustment() ADEMONO_REQUIRES(map_.mutex);
  // A global bundle adjustment of the whole map now, on this thread (`loop.global_ba_on_save`:
  // before the map is written). Any pending one is merged first. Not a loop event.
  void GlobalBundleAdjustmentNow() ADEMONO_REQUIRES(map_.mutex);

  // A verified loop: the candidate, match_cam_from_query_cam and the candidate's map points
  // matched to the query's keypoints (null where none).
  struct Verified {
    KeyFrame* match = nullptr;
    Sim3d match_from_query;
    std::vector<std::shared_ptr<MapPoint>> matched;
    int inliers = 0;
    int matches = 0;
  };
  // Geometric verification of one candidate (steps 2 above); public for tests.
  std::optional<Verified> Verify(KeyFrame& query, KeyFrame& candidate) const
      ADEMONO_REQUIRES(map_.mutex);
  // For the analysis (core/thread_annotations.h): the caller holds the map's mutex under another
  // name. Checked at run time.
  void AssertMapHeld() const ADEMONO_ASSERT_CAPABILITY(map_.mutex) { map_.mutex.AssertHeld(); }

 private:
  void Correct(KeyFrame& query, const Verified& loop, LoopEvent& event)
      ADEMONO_REQUIRES(map_.mutex);

  // A global BA between its gather and its merge. The worker writes only `result`, `failure` and
  // `ms`; the tracking thread reads them after joining it.
  struct GlobalBa {
    BundleAdjustmentProblem problem;
    std::vector<std::shared_ptr<KeyFrame>> keyframes;  // one per camera
    std::vector<std::shared_ptr<MapPoint>> points;     // one per problem point
    std::optional<BundleAdjustmentResult> result;
    std::exception_ptr failure;
    double ms = 0;
    std::optional<size_t> event;  // index into events_; none for the one before a map is saved
    int keyframes_since = 0;   // keyframes processed since the gather
    std::thread worker;
  };
  void StartGlobalBundleAdjustment(std::optional<size_t> event) ADEMONO_REQUIRES(map_.mutex);
  // Joins the solve; applies it when `apply`, else drops it.
  void EndGlobalBundleAdjustment(bool apply, uint64_t at_keyframe) ADEMONO_REQUIRES(map_.mutex);

  Map& map_;
  const KeyFrameDatabase& database_;
  LoopOptions options_;
  bool sim3_;
  double fuse_radius_;
  // Places verified for the previous keyframes: (keyframe ids of the place, consecutive count).
  std::vector<std::pair<std::set<uint64_t>, int>> groups_;
  std::vector<std::pair<uint64_t, uint64_t>> loop_edges_;  // of every closed loop
  uint64_t last_loop_keyframe_ = 0;
  bool any_loop_ = false;
  std::vector<LoopEvent> events_;
  std::unique_ptr<GlobalBa> global_ba_;
};

}  // namespace ademono
