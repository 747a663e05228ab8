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

#include "ademono/core/geometry.h"

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
  // A map point's position is known only as well as the depth that made it: along the ray of the
  // keyframe that measured it (its reference), with that depth's sigma. Seen from another place,
  // that uncertainty is a shift in the image, large for near points passed at speed. Both
  // residual thresholds grow by `parallax_sigmas` times that shift (ParallaxShiftPx at
  // PointDepthSigma, in the keypoint level's pixels). The sigma is the depth's error model when
  // it has one, else sigma_z / z = point_sigma_relative + point_sigma_per_metre * z: 0 for a
  // sensor by default (fixed pixel thresholds; a walker's points in a map made inside a crowd
  // would hide within a 5 % band's shift), the simulated network's own noise in street.yaml.
  double parallax_sigmas = 3.0;
  double point_sigma_relative = 0.0;
  double point_sigma_per_metre = 0.0;
  // The same sigma in the depth comparison: the map's depth (made at the reference distance) and
  // the measured one each carry it, so the static and motion bands widen to these multiples of
  // their combined sigma when that is wider (a depth without an error model: 2 and 4 sigmas, the
  // usual bounds of agreement and of a clear outlier; with 1 % + 0.1 %/m at 30 m the two depths
  // differ by more than the fixed 5 % band in two comparisons of five).
  double point_depth_sigmas = 2.0;
  double point_depth_dynamic_sigmas = 4.0;
  // The map's depth of a point carries the error of the depth that made it, a fraction of the
  // distance it was measured at: approached at speed (made at 30 m, seen at 20 m), that is a
  // larger fraction of the depth measured now. true: the depth bands are relative to the larger
  // of the measured depth and the point's distance from its reference keyframe; false: to the
  // measured depth alone.
  bool depth_at_reference = true;
  // true: a new keyframe point is also judged in the frame before the keyframe (found there by
  // projection), whose pose was computed without it: agreeing there admits it now instead of at
  // the next frame that matches it. Off by default: when the map starts inside a crowd, walkers
  // that barely moved in one frame were admitted a frame earlier and the map lost its way
  // (bonn-crowd-a frames 300-359: 10 frames untracked instead of 0). configs/street.yaml turns
  // it on (points pass out of view within a few frames at 10 m/s).
  bool confirm_in_last_frame = false;

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
// `residual_allowance_px` widens both residual thresholds (the point's own position
// uncertainty seen from this frame, ParallaxShiftPx times parallax_sigmas).
// `point_relative_sigma` is the combined sigma of the two compared depths from the configured
// point sigma (PointDepthDisagreementSigma), judged at point_depth_sigmas and
// point_depth_dynamic_sigmas.
StaticEvidence JudgeObservation(double residual_px, std::optional<double> depth_relative_error,
                                const StaticTestParams& params, double depth_relative_sigma = 0.0,
                                double residual_allowance_px = 0.0,
                                double point_relative_sigma = 0.0);

// The disagreement |z_map - z_measured| the depth bands judge, relative to z_measured, or with
// `depth_at_reference` to the larger of z_measured and `reference_distance` (the point's distance
// from the keyframe whose depth made it; <= 0 or not finite: unknown, z_measured alone).
double RelativeDepthDisagreement(double z_map, double z_measured, double reference_distance,
                                 const StaticTestParams& params);

// sigma_z / z of a map point's depth measured at `distance`: the larger of the configured
// point_sigma_relative + point_sigma_per_metre * distance and the depth's error model
// (`model_relative_sigma`, 0 without one).
double PointDepthSigma(double distance, const StaticTestParams& params,
                       double model_relative_sigma = 0.0);

// The sigma of RelativeDepthDisagreement from the configured point sigma alone (not an error
// model's): the map's depth measured at `reference_distance` and the depth `z_measured`, each
// with sigma_z = z (point_sigma_relative + point_sigma_per_metre z), combined in quadrature and
// relative to the same scale RelativeDepthDisagreement divides by. 0 when no sigma is configured.
double PointDepthDisagreementSigma(double z_measured, double reference_distance,
                                   const StaticTestParams& params);

// How far (pixels, pinhole with focal lengths fx, fy) the projection into `cam_from_world` of
// `point_world` moves when the point slides along the ray from `ray_origin_world` (the camera
// centre that measured its depth) by `relative_depth` of its distance, nearer or farther (the
// larger of the two). 0 seen from the ray's own origin; grows with the parallax between the two
// views. Infinite when a shifted point lands behind the camera.
double ParallaxShiftPx(const Eigen::Vector3d& point_world, const Eigen::Vector3d& ray_origin_world,
                       const Rigid3d& cam_from_world, double fx, double fy,
                       double relative_depth);

// Bayes update of P(static) by one verdict (likelihood ratios 1.5 for static, 1/4 for motion),
// clamped to [0.02, 0.98] so that a point can always change its mind.
double UpdateStaticProbability(double probability, StaticEvidence evidence);

}  // namespace ademono
