#include "ademono/core/statistics.h"

#include <algorithm>
#include <cmath>

namespace ademono {

double Median(std::vector<double> values) {
  const size_t n = values.size();
  if (n == 0) return 0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(values.begin(), mid, values.end());
  const double upper = *mid;
  if (n % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(), mid));
}

double RobustSpread(const std::vector<double>& values, double centre) {
  std::vector<double> deviations;
  deviations.reserve(values.size());
  for (double v : values) deviations.push_back(std::abs(v - centre));
  return 1.4826 * Median(std::move(deviations));
}

}  // namespace ademono
