#pragma once
// Geometric test for movers without a box (CFP-SLAM-style static probability of map points).
// Each map point carries P(static). Every frame that matches a point judges it at the frame's
// final pose: a small reprojection residual and a depth that agrees with the map are evidence of a
// static point; a residual or depth disagreement well beyond the noise is evidence of motion. The
// evidence accumulates as log-odds over the point's history, so one noisy frame does not remove a
// long-standing static point, while a walker's points fall below the threshold within a frame or
// two. Points below the threshold are matched and judged (they may turn out static after all) but
// never used for the pose. Boxes only lower the prior of the points created inside them.

#include <optional>

namespace ademono {

template <typename Options>
class OptionsTable;

struct StaticTestParams {
  double prior = 0.45;           // P(static) of a point created from a keyframe's depth
  double box_prior = 0.2;        // ... created inside a detector's dynamic box
  double threshold = 0.5;        // points below it are not used for the pose
  double residual_px = 2.5;      // reprojection residual (level-0 px) below: static evidence
  double residual_dynamic_px = 6.0;  // above: evidence of motion
  double depth_relative = 0.05;  // |z_map - z_measured| / z_measured below: static evidence ...
  double depth_dynamic_relative = 0.15;  // ... above: evidence of motion
  // A depth with an error model (network depth) is judged against its own sigma: the two bands
  // above widen to depth_sigmas and depth_dynamic_sigmas times sigma_z / z when that is wider
  // (a learned depth's 15-50 % error would otherwise read every static point as moving).
  double depth_sigmas = 0.5;
  double depth_dynamic_sigmas = 1.0;

  // Its keys of the flat `tracking:` node (static_prior, ...; TrackingOptions holds them).
  static const OptionsTable<StaticTestParams>& Table();
  bool operator==(const StaticTestParams&) const = default;
};

enum class StaticEvidence { kNone, kStatic, kDynamic };

// The verdict of one observation: `residual_px` the reprojection residual at the frame's pose in
// level-0 pixels, `depth_relative_error` |z_map - z_measured| / z_measured when the keypoint has a
// depth. Motion in either is evidence of motion; static needs both (when depth is known) agreeing.
// `depth_relative_sigma` is the depth's error model sigma_z / z at the measured depth (0: a
// sensor, judged by the fixed bands alone).
StaticEvidence JudgeObservation(double residual_px, std::optional<double> depth_relative_error,
                                const StaticTestParams& params, double depth_relative_sigma = 0.0);

// Bayes update of P(static) by one verdict (likelihood ratios 1.5 for static, 1/4 for motion),
// clamped to [0.02, 0.98] so that a point can always change its mind.
double UpdateStaticProbability(double probability, StaticEvidence evidence);

}  // namespace ademono
