#include "ademono/eval/shared_error.h"

#include <cmath>
#include <map>
#include <stdexcept>

namespace ademono {
namespace {

// Position error of each matched pose, keyed by the ground truth's timestamp.
std::map<double, Eigen::Vector3d> Errors(const EvalResult& r) {
  std::map<double, Eigen::Vector3d> errors;
  for (size_t i = 0; i < r.gt_matched.size() && i < r.est_aligned.size(); ++i) {
    errors.emplace(r.gt_matched.timestamps[i],
                   r.est_aligned.world_from_cam[i].block<3, 1>(0, 3) -
                       r.gt_matched.world_from_cam[i].block<3, 1>(0, 3));
  }
  return errors;
}

}  // namespace

SharedError ComputeSharedError(const EvalResult& a, const EvalResult& b) {
  const std::map<double, Eigen::Vector3d> ea = Errors(a), eb = Errors(b);
  double aa = 0, bb = 0, ab = 0, sum = 0, difference = 0;
  size_t n = 0;
  for (const auto& [stamp, e] : ea) {
    const auto it = eb.find(stamp);
    if (it == eb.end()) continue;
    const Eigen::Vector3d& f = it->second;
    aa += e.squaredNorm();
    bb += f.squaredNorm();
    ab += e.dot(f);
    sum += (0.5 * (e + f)).squaredNorm();
    difference += (0.5 * (e - f)).squaredNorm();
    ++n;
  }
  if (n < 3) {
    throw std::invalid_argument("the two estimates match " + std::to_string(n) +
                                " ground-truth poses in common (at least 3 needed)");
  }
  SharedError r;
  r.frames = n;
  r.rmse_a = std::sqrt(aa / n);
  r.rmse_b = std::sqrt(bb / n);
  r.shared_rmse = std::sqrt(sum / n);
  r.half_difference_rmse = std::sqrt(difference / n);
  r.correlation = aa > 0 && bb > 0 ? ab / std::sqrt(aa * bb) : 0;
  return r;
}

nlohmann::json SharedError::ToJson() const {
  return {{"frames", frames},
          {"rmse_a", rmse_a},
          {"rmse_b", rmse_b},
          {"shared_rmse", shared_rmse},
          {"half_difference_rmse", half_difference_rmse},
          {"correlation", correlation}};
}

}  // namespace ademono
