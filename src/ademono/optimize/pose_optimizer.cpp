#include "ademono/optimize/pose_optimizer.h"

#include <stdexcept>

#include "ademono/core/options_table.h"
#include "ademono/optimize/residuals.h"

namespace ademono {

const OptionsTable<PoseOptimizerOptions>& PoseOptimizerOptions::Table() {
  using P = PoseOptimizerOptions;
  static const auto table =
      OptionsTable<P>("optimizer")
          .Add("pose_rounds", &P::rounds, Range::AtLeast(1))
          .Add("pose_iterations_per_round", &P::iterations_per_round, Range::AtLeast(1))
          .AddChoice<bool>("pose_jacobians", &P::analytic_jacobians,
                           {{"analytic", true}, {"autodiff", false}});
  return table;
}

void PoseOptimizerOptions::Check() const { Table().CheckRanges(*this); }

namespace {
template <int kDim>
ceres::CostFunction* MakeCost(bool analytic, const PinholeIntrinsics& intrinsics,
                              const PoseObservation& o) {
  if (analytic) return new internal::AnalyticPoseCost<kDim>(intrinsics, o.image, o.point_world);
  return new ceres::AutoDiffCostFunction<internal::PoseOnlyResidual<kDim>, kDim, 6>(
      new internal::PoseOnlyResidual<kDim>(intrinsics, o.image, o.point_world));
}
}  // namespace

PoseOptimizationResult OptimizePose(const PinholeIntrinsics& intrinsics,
                                    const Rigid3d& initial_cam_from_world,
                                    const std::vector<PoseObservation>& observations,
                                    const PoseOptimizerOptions& options) {
  options.Check();
  PoseOptimizationResult result;
  result.cam_from_world = initial_cam_from_world;
  result.outlier.assign(observations.size(), false);
  if (observations.empty()) return result;

  double camera[6];
  internal::RigidToParams(initial_cam_from_world, camera);

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.iterations_per_round;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;

  for (int round = 0; round < options.rounds; ++round) {
    // ORB-SLAM keeps the robust kernel for the first two rounds only: by then the outliers are
    // out and the plain least squares gives the best estimate for the inliers.
    const bool robust = round < 2 || options.robust_last_round;
    ceres::Problem problem;
    int added = 0;
    for (size_t i = 0; i < observations.size(); ++i) {
      if (result.outlier[i]) continue;
      const PoseObservation& o = observations[i];
      if (o.image.HasDepth()) {
        problem.AddResidualBlock(MakeCost<3>(options.analytic_jacobians, intrinsics, o),
                                 robust ? new ceres::HuberLoss(std::sqrt(kChi2Stereo)) : nullptr,
                                 camera);
      } else {
        problem.AddResidualBlock(MakeCost<2>(options.analytic_jacobians, intrinsics, o),
                                 robust ? new ceres::HuberLoss(std::sqrt(kChi2Mono)) : nullptr,
                                 camera);
      }
      ++added;
    }
    if (added < 3) break;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);

    const Rigid3d pose = internal::ParamsToRigid(camera);
    result.num_inliers = 0;
    for (size_t i = 0; i < observations.size(); ++i) {
      const PoseObservation& o = observations[i];
      const double chi2 =
          internal::ObservationChi2(intrinsics, o.image, pose, o.point_world, nullptr);
      result.outlier[i] = chi2 > (o.image.HasDepth() ? kChi2Stereo : kChi2Mono);
      if (!result.outlier[i]) ++result.num_inliers;
    }
    if (result.num_inliers < 10) break;
  }
  result.cam_from_world = internal::ParamsToRigid(camera);
  return result;
}

}  // namespace ademono
