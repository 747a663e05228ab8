#pragma once
// Motion-only pose optimisation (ORB-SLAM's PoseOptimization): the camera pose is refined
// against fixed 3D points, Huber loss (delta = sqrt(chi2 threshold)), 4 rounds with outlier
// classification by chi2 after each round; outliers are left out of the next round and may come
// back if they fit the refined pose. Single-threaded and deterministic.
// Two solvers of the same problem: a small Levenberg-Marquardt on the 6x6 normal equations with
// the analytic Jacobians (`lm`, default: it follows Ceres' trust-region strategy, Jacobi scaling
// and stopping rules, without Ceres' per-call problem setup, about 5x cheaper), or Ceres itself
// (`ceres`, needed for auto-diff Jacobians). Their poses agree to ~1e-9, not bit for bit.

#include <yaml-cpp/yaml.h>

#include <vector>

#include "ademono/optimize/optimizer_types.h"

namespace ademono {

template <typename Options>
class OptionsTable;

struct PoseOptimizerOptions {
  int rounds = 4;
  int iterations_per_round = 10;
  bool robust_last_round = false;  // ORB-SLAM drops the robust kernel in the last rounds
  bool analytic_jacobians = true;  // false: Ceres auto-diff (needs use_ceres)
  bool use_ceres = false;          // false: the built-in Levenberg-Marquardt
  void Check() const;              // throws std::invalid_argument
  // The `optimizer:` node: pose_rounds, pose_iterations_per_round, pose_jacobians
  // (analytic|autodiff), pose_solver (lm|ceres); robust_last_round is fixed.
  static const OptionsTable<PoseOptimizerOptions>& Table();
  bool operator==(const PoseOptimizerOptions&) const = default;
};

struct PoseObservation {
  Eigen::Vector3d point_world = Eigen::Vector3d::Zero();
  ImageObservation image;
};

struct PoseOptimizationResult {
  Rigid3d cam_from_world = Rigid3d::Identity();
  std::vector<bool> outlier;  // one per observation
  int num_inliers = 0;
};

// `initial_cam_from_world` is the starting pose. With no observation it is returned unchanged.
PoseOptimizationResult OptimizePose(const PinholeIntrinsics& intrinsics,
                                    const Rigid3d& initial_cam_from_world,
                                    const std::vector<PoseObservation>& observations,
                                    const PoseOptimizerOptions& options = {});

}  // namespace ademono
