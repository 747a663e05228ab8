#pragma once
// What two estimates' errors against one ground truth have in common. Two methods that share
// only the images (say, SLAM on sensor depth and SLAM on no depth at all) make independent
// errors of their own; what they share is in the images (calibration, rolling shutter) or in the
// ground truth itself. On 7-Scenes seq-a, whose poses are KinectFusion's (a pseudo ground truth),
// the monocular and the RGB-D runs share 0.029 m of their 0.03 m (docs/evaluation.md "Errors two
// runs share").

#include <cstddef>
#include <nlohmann/json.hpp>

#include "ademono/eval/trajectory_eval.h"

namespace ademono {

struct SharedError {
  size_t frames = 0;  // ground-truth poses both estimates matched
  // RMS over those frames of |e_a|, |e_b|, |(e_a + e_b) / 2| and |(e_a - e_b) / 2|, e the
  // position error of an estimate after its own alignment (metres).
  double rmse_a = 0, rmse_b = 0, shared_rmse = 0, half_difference_rmse = 0;
  // sum e_a . e_b / sqrt(sum |e_a|^2 sum |e_b|^2): 1 the same error, 0 independent ones.
  double correlation = 0;
  nlohmann::json ToJson() const;
};

// From two EvaluateTrajectories results against the same ground truth (their gt_matched and
// est_aligned). Throws std::invalid_argument when fewer than 3 ground-truth poses are matched by
// both.
SharedError ComputeSharedError(const EvalResult& a, const EvalResult& b);

}  // namespace ademono
