#pragma once
// Scores a run's per-keypoint filter labels against a synthetic sequence's truth
// (`ademono synth` writes masks/<frame name>.png of moving objects): how many keypoints on moving
// objects the dynamic filter removed, and how many on a static person-class object (the office
// mannequin). Used by the ablation (runner/ablation.h).

#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "ademono/filter/feature_filter.h"
#include "ademono/io/sequence.h"
#include "ademono/perception/detection.h"
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
  nlohmann::json ToJson() const;
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
  void Score(const FrameData& frame, const std::vector<Detection>& detections,
             const std::vector<cv::KeyPoint>& keypoints, const std::vector<PointLabel>& labels,
             TruthCounts* counts, const std::vector<MatchState>* match_state = nullptr) const;

 private:
  std::filesystem::path masks_dir_;
  bool available_ = false;
};

}  // namespace ademono
