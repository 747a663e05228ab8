#include "ademono/slam/static_probability.h"

#include <algorithm>
#include <cmath>

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
          .Add("static_depth_dynamic_sigmas", &P::depth_dynamic_sigmas, Range::Above(0));
  return table;
}

StaticEvidence JudgeObservation(double residual_px, std::optional<double> depth_relative_error,
                                const StaticTestParams& params, double depth_relative_sigma) {
  if (!std::isfinite(residual_px)) return StaticEvidence::kDynamic;
  const bool depth_known = depth_relative_error && std::isfinite(*depth_relative_error);
  const double sigma = std::isfinite(depth_relative_sigma) ? std::max(depth_relative_sigma, 0.0) : 0.0;
  const double static_band = std::max(params.depth_relative, params.depth_sigmas * sigma);
  const double dynamic_band =
      std::max(params.depth_dynamic_relative, params.depth_dynamic_sigmas * sigma);
  if (residual_px > params.residual_dynamic_px ||
      (depth_known && *depth_relative_error > dynamic_band))
    return StaticEvidence::kDynamic;
  if (residual_px <= params.residual_px &&
      (!depth_known || *depth_relative_error <= static_band))
    return StaticEvidence::kStatic;
  return StaticEvidence::kNone;
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
