#pragma once
// Parameters of dynamic interference removal (filter/dynamic.h), the `dynamic` part of
// FilterOptions. Read from the flat `filter:` YAML node (filter.box_growth, ...; docs/filters.md).

#include <string>
#include <vector>

#include "ademono/perception/detection.h"

namespace ademono {

template <typename Options>
class OptionsTable;

struct DynamicParams {
  double box_growth = 0.02;            // d = box_growth * box diagonal on every side
  double small_box_area_ratio = 0.05;  // box area / image area below this: a small target
  // true: small targets go through stage 1/2 and the box vote like large ones (a far parked car
  // whose points agree with the camera motion keeps them). false (default): the paper's rule,
  // every point in a small box is dropped (kDynamicSmallBox). Off by default: on the synthetic
  // street ring the kept parked-car points ruined the loop correction (docs/filters.md).
  bool judge_small_boxes = false;
  int background_matches_t = 20;       // t smallest-Hamming background matches
  double d_dis_px = 8.0;               // stage 1 threshold D_dis (pixels)
  double d_min_px = 4.0;               // stage 2 threshold D_min (pixels)
  // Stage 1 against the camera motion fitted to the background (PnP on previous depths), not the
  // paper's one mean displacement, which misjudges static objects under forward motion.
  bool stage1_motion_compensation = true;
  int motion_min_inliers = 12;    // background matches the fit needs (and inliers it keeps)
  double motion_inlier_px = 3.0;  // RANSAC reprojection threshold of the fit
  int motion_ransac_iterations = 100;
  // How stage 1 judges a large box's point. "depth": against the camera motion and the depths
  // above, then stage 2 against the predicted pose (what the paper's tests need). "epipolar": by
  // the point's distance from its epipolar line under the camera's motion (the pose prediction
  // refined on the background's matches; without poses a fundamental matrix fitted to them), so
  // no depth: a network's depth error cannot fail a static point (outdoors at 10 m/s it failed
  // 30-96 % of the background around parked cars, docs/kitti.md). A mover along its epipolar
  // line (a car ahead in the same lane) passes; stage 2 is not run.
  std::string dynamic_test = "depth";
  double epipolar_px = 2.0;  // RANSAC threshold of the fit and the test's (pixels)
  // Box vote for large-box points without a stage-1/2 verdict: a box is moving when at least this
  // fraction of its judged points (and at least box_vote_min_matches of them) failed stage 1 or 2.
  // > 1 disables.
  double box_vote_ratio = 0.15;
  int box_vote_min_matches = 5;
  // The vote spares a point whose depth is beyond this times the mover's depth (the median depth of
  // the box's points that failed stage 1 or 2, when at least three have one): the background seen
  // around the mover inside its box. 0 votes every point without a verdict away, as before.
  double box_vote_depth_ratio = 1.3;
  std::vector<int> dynamic_class_ids = DefaultDynamicClassIds();
  // Frame-to-frame matching for stage 1 (ORB-SLAM's usual values; not in the YAML).
  double match_ratio = 0.8;
  int match_max_distance = 100;

  void Check() const;  // throws std::invalid_argument("filter.<key> ...")
  // Its keys of the flat `filter:` node (FilterOptions::Table() holds them in place).
  static const OptionsTable<DynamicParams>& Table();
  bool operator==(const DynamicParams&) const = default;
};

}  // namespace ademono
