#include "ademono/optimize/depth_scale.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ademono/core/statistics.h"

namespace ademono {

void DepthScaleOptions::Check() const {
  if (min_points < 1) throw std::invalid_argument("depth scale: min_points must be >= 1");
  if (!(huber_k > 0)) throw std::invalid_argument("depth scale: huber_k must be > 0");
  if (iterations < 0) throw std::invalid_argument("depth scale: iterations must be >= 0");
  if (!(min_sigma > 0)) throw std::invalid_argument("depth scale: min_sigma must be > 0");
}

DepthScaleEstimate EstimateDepthScale(const std::vector<double>& reference,
                                      const std::vector<double>& source,
                                      const DepthScaleOptions& options) {
  options.Check();
  if (reference.size() != source.size()) {
    throw std::invalid_argument("EstimateDepthScale: reference and source differ in size");
  }
  std::vector<double> logs;
  logs.reserve(reference.size());
  for (size_t i = 0; i < reference.size(); ++i) {
    const double r = reference[i], s = source[i];
    if (std::isfinite(r) && std::isfinite(s) && r > 0 && s > 0) logs.push_back(std::log(r / s));
  }
  DepthScaleEstimate estimate;
  estimate.num_points = static_cast<int>(logs.size());
  if (estimate.num_points < options.min_points) return estimate;

  const double median = Median(logs);
  const double sigma = std::max(options.min_sigma, RobustSpread(logs, median));

  // Huber IRLS on the location of the log ratios, started at the median.
  double mu = median;
  const double threshold = options.huber_k * sigma;
  double weight_sum = 0;
  for (int it = 0; it < options.iterations; ++it) {
    double sum = 0;
    weight_sum = 0;
    for (double l : logs) {
      const double r = std::abs(l - mu);
      const double w = r <= threshold ? 1.0 : threshold / r;
      sum += w * l;
      weight_sum += w;
    }
    const double next = sum / weight_sum;
    const bool converged = std::abs(next - mu) < 1e-9;
    mu = next;
    if (converged) break;
  }
  if (options.iterations == 0) weight_sum = static_cast<double>(logs.size());
  estimate.valid = true;
  estimate.scale = std::exp(mu);
  estimate.log_sigma = sigma;
  estimate.log_stderr = sigma / std::sqrt(std::max(1.0, weight_sum));
  return estimate;
}

}  // namespace ademono
