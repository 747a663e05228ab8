#include "ademono/optimize/network_depth_model.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include "ademono/core/statistics.h"

namespace ademono {
namespace {

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

// The rms of the depth bins' median residuals beyond their sampling noise (a median of n
// samples of spread s scatters by about s * sqrt(pi / (2 n))).
double SharedSpread(std::vector<std::pair<double, double>> by_depth,
                    const InverseDepthAffineOptions& options) {
  const size_t bins = static_cast<size_t>(std::max(1, options.depth_bins));
  const size_t per_bin = by_depth.size() / bins;
  if (bins < 2 || per_bin < static_cast<size_t>(std::max(2, options.min_points_per_bin)))
    return 0.0;
  std::sort(by_depth.begin(), by_depth.end());
  double sum = 0.0;
  for (size_t b = 0; b < bins; ++b) {
    const size_t end = b + 1 == bins ? by_depth.size() : (b + 1) * per_bin;
    std::vector<double> r;
    for (size_t i = b * per_bin; i < end; ++i) r.push_back(by_depth[i].second);
    const double median = Median(r);
    const double spread = RobustSpread(r, median);
    const double noise = spread * spread * std::numbers::pi / (2.0 * static_cast<double>(r.size()));
    sum += std::max(0.0, median * median - noise);
  }
  return std::sqrt(sum / static_cast<double>(bins));
}

}  // namespace

InverseDepthAffine FitInverseDepthAffine(const std::vector<double>& map_depths,
                                         const std::vector<double>& network_depths,
                                         const InverseDepthAffineOptions& options) {
  InverseDepthAffine fit;
  std::vector<double> zm, zn, ratios, inverse;
  for (size_t i = 0; i < std::min(map_depths.size(), network_depths.size()); ++i) {
    const double m = map_depths[i], n = network_depths[i];
    if (!(m > 0) || !(n > 0) || !std::isfinite(m) || !std::isfinite(n)) continue;
    zm.push_back(m);
    zn.push_back(n);
    ratios.push_back(n / m);
    inverse.push_back(1.0 / n);
  }
  fit.num_points = static_cast<int>(zm.size());
  if (fit.num_points < options.min_points) return fit;
  fit.median_ratio = Median(ratios);
  fit.a = fit.median_ratio;  // 1 / z_map = a / z_net at the median
  fit.b = 0.0;
  const double low = Quantile(inverse, 0.1), high = Quantile(inverse, 0.9);
  fit.scale_only = !(low > 0) || high / low < options.min_inverse_depth_span;

  const size_t n = zm.size();
  std::vector<double> residuals(n);
  auto compute_residuals = [&]() {
    for (size_t i = 0; i < n; ++i) residuals[i] = 1.0 - zm[i] * (fit.a / zn[i] + fit.b);
  };
  compute_residuals();
  for (int it = 0; it < options.iterations; ++it) {
    const double sigma = std::max(RobustSpread(residuals), 1e-6);
    // Huber first (convex: settles near the bulk), then Tukey's biweight, which gives points far
    // off (wrong matches, movers) no weight at all.
    const bool tukey = it >= 3;
    const double k = (tukey ? 4.685 : options.huber_sigmas) * sigma;
    // Weighted normal equations of r_i = 1 - a x_i - b y_i, x_i = z_map / z_net, y_i = z_map.
    Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
    Eigen::Vector2d g = Eigen::Vector2d::Zero();
    for (size_t i = 0; i < n; ++i) {
      const double r = std::abs(residuals[i]);
      double w = 0.0;
      if (tukey) {
        w = r < k ? std::pow(1.0 - (r / k) * (r / k), 2) : 0.0;
      } else {
        w = r <= k ? 1.0 : k / r;
      }
      const Eigen::Vector2d j(zm[i] / zn[i], zm[i]);
      A += w * j * j.transpose();
      g += w * j;
    }
    double a = fit.a, b = 0.0;
    if (fit.scale_only) {
      if (!(A(0, 0) > 0)) break;
      a = g(0) / A(0, 0);
    } else {
      const Eigen::Vector2d x = A.ldlt().solve(g);
      if (!x.allFinite()) break;
      a = x(0);
      b = x(1);
    }
    const bool converged = std::abs(a - fit.a) <= 1e-12 * std::abs(fit.a) &&
                           std::abs(b - fit.b) <= 1e-12 * (std::abs(fit.b) + std::abs(a));
    fit.a = a;
    fit.b = b;
    compute_residuals();
    if (converged && tukey) break;
  }
  if (!(fit.a > 0) || !std::isfinite(fit.a) || !std::isfinite(fit.b)) return fit;
  // The spread of the points the fit kept (within 3 robust sigmas).
  std::vector<double> log_residuals;
  std::vector<std::pair<double, double>> by_depth;  // (z_net, log residual) of the inliers
  const double sigma = RobustSpread(residuals);
  for (size_t i = 0; i < n; ++i) {
    if (std::abs(residuals[i]) > 3.0 * sigma) continue;
    ++fit.num_inliers;
    const double mapped = fit.Map(zn[i]);
    if (mapped > 0) {
      log_residuals.push_back(std::log(zm[i] / mapped));
      by_depth.emplace_back(zn[i], log_residuals.back());
    }
  }
  fit.sigma_log = RobustSpread(log_residuals);
  fit.shared_sigma_log = SharedSpread(by_depth, options);
  fit.valid = true;
  return fit;
}

}  // namespace ademono
