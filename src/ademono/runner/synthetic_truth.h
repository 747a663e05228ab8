#pragma once
// Scores a run's per-keypoint filter labels against a synthetic sequence's truth
// (`ademono synth` writes masks/<frame name>.png of moving objects): how many keypoints on moving
// objects the dynamic filter removed, and how many on a static person-class object (the office
// mannequin). Used by the ablation (runner/ablation.h).

#include <array>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "ademono/filter/feature_filter.h"
#include "ademono/io/sequence.h"
#include "ademono/perception/detection.h"
#include "ademono/slam/map_point.h"
#include "ademono/slam/tracking.h"

namespace ademono {

// Keypoints scored against synthetic ground truth. Only keypoints that reach the dynamic filter
// count (not dropped by the enhancement before it), and only dynamic-removal labels count as
// removed (a distant drop is not the dynamic filter's doing), plus, when the tracking's match
// states are given, keypoints whose matched map point the geometric test keeps out of the pose
// (unconfirmed or judged moving; slam/tracking.h MatchState).
struct TruthCounts {
  // Keypoints the filter kept, by what tracking made of them (MatchState order: unmatched, pose
  // inlier, pose outlier, unconfirmed, judged moving).
  using StateCounts = std::array<long long, 5>;
  long long moving_keypoints = 0;         // keypoints whose pixel is in the moving-object mask
  long long moving_removed = 0;           // ... labelled dynamic
  long long moving_kept = 0;              // ... labelled kept (used for tracking)
  StateCounts moving_kept_by_state{};
  // Moving keypoints outside every box of a dynamic class: movers the detector did not box
  // (synth's movers of no COCO class, missed persons and cars). Removing them takes geometry.
  long long moving_unboxed_keypoints = 0;
  long long moving_unboxed_removed = 0;  // ... labelled dynamic
  // Moving keypoints not removed: within 2 px of a static pixel (the mover's outline, whose ORB
  // patch is half background), and outside every box.
  long long moving_not_removed_at_edge = 0;
  long long moving_not_removed_unboxed = 0;
  // Every keypoint not on a moving object (the static scene, boxed or not).
  long long static_keypoints = 0;
  long long static_removed = 0;  // ... labelled dynamic
  StateCounts static_kept_by_state{};
  long long static_person_keypoints = 0;  // in the static person box, not on a moving object
  long long static_person_removed = 0;    // ... labelled dynamic
  // In any box of a dynamic class (the detector's box, not grown) but not on a moving object:
  // static objects such as parked cars, and background seen inside boxes.
  long long static_in_box_keypoints = 0;
  long long static_in_box_removed = 0;  // ... labelled dynamic
  // What removed the static keypoints (each counted once, the filter's label first): the box
  // filter's small box / stage 1 / stage 2 / box vote, and the geometric test alone (its map
  // point unconfirmed, or judged moving).
  long long static_removed_small_box = 0;
  long long static_removed_stage1 = 0;
  long long static_removed_stage2 = 0;
  long long static_removed_box_vote = 0;
  long long static_removed_unconfirmed = 0;
  long long static_removed_judged_moving = 0;
  // Static keypoints within 2 px of a moving object's pixels: corners on a mover's silhouette,
  // whose ORB patch is half mover (which side of the outline the rounded pixel falls is chance).
  long long static_at_mover_edge_keypoints = 0;
  long long static_at_mover_edge_removed = 0;
  long long moving_removed_geometric = 0;  // moving keypoints only the geometric test removed
  // Whether a keypoint fed tracking or the map: a pose inlier, or the source of a new keyframe
  // point that was ever admitted into the pose and BA (MapPoint::admitted, known at the end of
  // the run). Every other moving keypoint is kept out: removed by a label or the geometric
  // test, rejected by the pose, unmatched, or its new point never confirmed by another view.
  long long moving_pose_inliers = 0;
  long long moving_new_points = 0;           // moving keypoints a new keyframe made points of
  long long moving_new_points_admitted = 0;  // ... whose point was admitted (entered the map)
  // Static keypoints a new keyframe made points of; those never admitted because the geometric
  // test judged them moving (kept out of the map: removed), and those never admitted without
  // such a verdict (never seen again, culled by local mapping, or no decisive view).
  long long static_new_points = 0;
  long long static_new_points_judged_out = 0;
  long long static_new_points_unconfirmed = 0;
  // Static keypoints removed (static_removed) plus those whose new point was judged out.
  long long static_kept_out = 0;
  // Moving keypoints that entered tracking or the map: pose inliers and admitted new points.
  long long MovingEntered() const { return moving_pose_inliers + moving_new_points_admitted; }
  nlohmann::json ToJson() const;
};

// A keypoint whose new map point's fate is known only at the end of the run.
struct PendingPoint {
  bool moving = false;
  bool already_removed = false;  // labelled dynamic or kept out by the geometric test
  std::shared_ptr<const MapPoint> point;
};

// Reads masks/<frame name>.png of a synthetic sequence and finds the static person box of a
// frame (a person box with under 20% moving pixels; the mannequin). Available() is false when
// the sequence has no masks/ folder.
class SyntheticTruth {
 public:
  explicit SyntheticTruth(const std::filesystem::path& sequence_dir);
  bool Available() const { return available_; }
  // Throws InputError when the frame's mask is missing or not the image size.
  // `match_state` (optional, per keypoint): what tracking made of each keypoint; an unconfirmed
  // or judged-moving one counts as removed like a dynamic label.
  // `created` (optional): the map points a new keyframe made from the frame's keypoints (index
  // into `keypoints`); they go to `pending`, to be counted by Resolve after the run.
  void Score(const FrameData& frame, const std::vector<Detection>& detections,
             const std::vector<cv::KeyPoint>& keypoints, const std::vector<PointLabel>& labels,
             TruthCounts* counts, const std::vector<MatchState>* match_state = nullptr,
             const std::vector<std::pair<size_t, std::shared_ptr<const MapPoint>>>* created =
                 nullptr,
             std::vector<PendingPoint>* pending = nullptr) const;
  // After the run (the map no longer changes): which pending new points were ever admitted,
  // following fusion (a point replaced by an admitted one entered the map through it).
  static void Resolve(const std::vector<PendingPoint>& pending, TruthCounts* counts);

 private:
  std::filesystem::path masks_dir_;
  bool available_ = false;
};

}  // namespace ademono
