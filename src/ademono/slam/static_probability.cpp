#include "ademono/slam/static_probability.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ademono/core/options_table.h"

namespace ademono {

const OptionsTable<StaticTestParams>& StaticTestParams::Table() {
  using P = StaticTestParams;
  static const auto table =
      OptionsTable<P>("tracking")
          .Add("static_prior", &P::prior, Range::Closed(0, 1))
          .Add("static_box_prior", &P::box_prior, Range::Closed(0, 1))
          .Add("static_threshold", &P::threshold, Range::Closed(0, 1))
          .Add("static_residual_px", &P::residual_px, Range::Above(0))
          .Add("static_residual_dynamic_px", &P::residual_dynamic_px, Range::Above(0))
          .Add("static_depth_relative", &P::depth_relative, Range::Above(0))
          .Add("static_depth_dynamic_relative", &P::depth_dynamic_relative, Range::Above(0))
          .Add("static_depth_sigmas", &P::depth_sigmas, Range::Above(0))
          .Add("static_depth_dynamic_sigmas", &P::depth_dynamic_sigmas, Range::Above(0))
          .Add("static_parallax_sigmas", &P::parallax_sigmas, Range::AtLeast(0))
          .Add("static_point_sigma_relative", &P::point_sigma_relative, Range::AtLeast(0))
          .Add("static_point_sigma_per_metre", &P::point_sigma_per_metre, Range::AtLeast(0))
          .Add("static_point_depth_sigmas", &P::point_depth_sigmas, Range::Above(0))
          .Add("static_point_depth_dynamic_sigmas", &P::point_depth_dynamic_sigmas,
               Range::Above(0))
          .Add("static_depth_at_reference", &P::depth_at_reference)
          .Add("static_confirm_in_last_frame", &P::confirm_in_last_frame);
  return table;
}

StaticEvidence JudgeObservation(double residual_px, std::optional<double> depth_relative_error,
                                const StaticTestParams& params, double depth_relative_sigma,
                                double residual_allowance_px, double point_relative_sigma) {
  if (!std::isfinite(residual_px)) return StaticEvidence::kDynamic;
  const double allowance =
      std::isfinite(residual_allowance_px) ? std::max(residual_allowance_px, 0.0) : 0.0;
  const bool depth_known = depth_relative_error && std::isfinite(*depth_relative_error);
  const double sigma =
      std::isfinite(depth_relative_sigma) ? std::max(depth_relative_sigma, 0.0) : 0.0;
  const double noise =
      std::isfinite(point_relative_sigma) ? std::max(point_relative_sigma, 0.0) : 0.0;
  const double static_band = std::max(
      {params.depth_relative, params.depth_sigmas * sigma, params.point_depth_sigmas * noise});
  const double dynamic_band =
      std::max({params.depth_dynamic_relative, params.depth_dynamic_sigmas * sigma,
                params.point_depth_dynamic_sigmas * noise});
  if (residual_px > params.residual_dynamic_px + allowance ||
      (depth_known && *depth_relative_error > dynamic_band))
    return StaticEvidence::kDynamic;
  if (residual_px <= params.residual_px + allowance &&
      (!depth_known || *depth_relative_error <= static_band))
    return StaticEvidence::kStatic;
  return StaticEvidence::kNone;
}

double RelativeDepthDisagreement(double z_map, double z_measured, double reference_distance,
                                 const StaticTestParams& params) {
  double scale = z_measured;
  if (params.depth_at_reference && std::isfinite(reference_distance))
    scale = std::max(scale, reference_distance);
  return std::abs(z_map - z_measured) / scale;
}

double PointDepthSigma(double distance, const StaticTestParams& params,
                       double model_relative_sigma) {
  const double configured = params.point_sigma_relative + params.point_sigma_per_metre * distance;
  const double model = std::isfinite(model_relative_sigma) ? model_relative_sigma : 0.0;
  return std::max({configured, model, 0.0});
}

double PointDepthDisagreementSigma(double z_measured, double reference_distance,
                                   const StaticTestParams& params) {
  if (!(z_measured > 0) || !std::isfinite(z_measured)) return 0.0;
  const bool has_reference = reference_distance > 0 && std::isfinite(reference_distance);
  const double z_map = has_reference ? reference_distance : z_measured;
  auto sigma_at = [&](double z) {
    return z * (params.point_sigma_relative + params.point_sigma_per_metre * z);
  };
  double scale = z_measured;
  if (params.depth_at_reference && has_reference) scale = std::max(scale, reference_distance);
  return std::hypot(sigma_at(z_map), sigma_at(z_measured)) / scale;
}

double ParallaxShiftPx(const Eigen::Vector3d& point_world, const Eigen::Vector3d& ray_origin_world,
                       const Rigid3d& cam_from_world, double fx, double fy,
                       double relative_depth) {
  const Eigen::Vector3d cam = cam_from_world * point_world;
  if (cam.z() <= 0) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d along = relative_depth * (point_world - ray_origin_world);
  double shift = 0;
  for (const double sign : {1.0, -1.0}) {
    const Eigen::Vector3d moved = cam_from_world * (point_world + sign * along);
    if (moved.z() <= 0) return std::numeric_limits<double>::infinity();
    shift = std::max(shift, std::hypot(fx * (moved.x() / moved.z() - cam.x() / cam.z()),
                                       fy * (moved.y() / moved.z() - cam.y() / cam.z())));
  }
  return shift;
}

double UpdateStaticProbability(double probability, StaticEvidence evidence) {
  // Motion is the stronger evidence: a walker must drop out after one or two frames, while a
  // static point needs several agreeing frames to be trusted fully.
  constexpr double kStaticRatio = 1.5, kDynamicRatio = 0.25;
  constexpr double kMin = 0.02, kMax = 0.98;
  if (evidence == StaticEvidence::kNone) return probability;
  const double p = std::clamp(probability, kMin, kMax);
  const double odds = p / (1.0 - p) * (evidence == StaticEvidence::kStatic ? kStaticRatio
                                                                            : kDynamicRatio);
  return std::clamp(odds / (1.0 + odds), kMin, kMax);
}

}  // namespace ademono
