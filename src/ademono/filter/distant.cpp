#include "ademono/filter/distant.h"

#include <cmath>
#include <stdexcept>

namespace ademono {

std::vector<bool> DrawDistantDrops(const std::vector<float>& depths,
                                   const std::vector<bool>& active, double z_th_m,
                                   double drop_probability, std::mt19937_64& rng) {
  if (!active.empty() && active.size() != depths.size())
    throw std::invalid_argument("DrawDistantDrops: one active flag per depth expected");
  std::vector<bool> drop(depths.size(), false);
  for (size_t i = 0; i < depths.size(); ++i) {
    if (!active.empty() && !active[i]) continue;
    const float d = depths[i];
    if (!std::isfinite(d) || d <= 0.f || d <= z_th_m) continue;
    drop[i] = UniformFromBits(rng()) < drop_probability;
  }
  return drop;
}

}  // namespace ademono
