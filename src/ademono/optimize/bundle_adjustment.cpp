#include "ademono/optimize/bundle_adjustment.h"

#include <stdexcept>

#include "ademono/core/options_table.h"
#include "ademono/optimize/residuals.h"

namespace ademono {

const OptionsTable<BundleAdjustmentOptions>& BundleAdjustmentOptions::Table() {
  using B = BundleAdjustmentOptions;
  static const auto table =
      OptionsTable<B>("mapping")
          .Add("ba_first_iterations", &B::first_iterations, Range::AtLeast(1))
          .Add("ba_second_iterations", &B::second_iterations, Range::AtLeast(0));
  return table;
}

void BundleAdjustmentOptions::Check() const { Table().CheckRanges(*this); }

namespace {

// Solves with the observations not flagged in `skip`; returns whether Ceres converged.
bool Solve(const BundleAdjustmentProblem& problem, const std::vector<bool>& skip, int iterations,
           std::vector<double>& cameras, std::vector<double>& points) {
  ceres::Problem ceres_problem;
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  std::vector<bool> point_used(problem.points.size(), false),
      camera_used(problem.cameras.size(), false);
  for (size_t i = 0; i < problem.observations.size(); ++i) {
    if (skip[i]) continue;
    const BaObservation& o = problem.observations[i];
    double* camera = &cameras[6 * o.camera];
    double* point = &points[3 * o.point];
    if (o.image.HasDepth()) {
      auto* cost = new ceres::AutoDiffCostFunction<internal::BaResidual<3>, 3, 6, 3>(
          new internal::BaResidual<3>(problem.intrinsics, o.image));
      ceres_problem.AddResidualBlock(cost, new ceres::HuberLoss(std::sqrt(kChi2Stereo)), camera,
                                     point);
    } else {
      auto* cost = new ceres::AutoDiffCostFunction<internal::BaResidual<2>, 2, 6, 3>(
          new internal::BaResidual<2>(problem.intrinsics, o.image));
      ceres_problem.AddResidualBlock(cost, new ceres::HuberLoss(std::sqrt(kChi2Mono)), camera,
                                     point);
    }
    point_used[o.point] = true;
    camera_used[o.camera] = true;
  }
  if (ceres_problem.NumResidualBlocks() == 0) return false;
  for (size_t c = 0; c < problem.cameras.size(); ++c) {
    if (!camera_used[c]) continue;
    if (problem.cameras[c].fixed) ceres_problem.SetParameterBlockConstant(&cameras[6 * c]);
    ordering->AddElementToGroup(&cameras[6 * c], 1);
  }
  for (size_t p = 0; p < problem.points.size(); ++p) {
    if (point_used[p]) ordering->AddElementToGroup(&points[3 * p], 0);
  }

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_SCHUR;
  options.linear_solver_ordering = ordering;
  options.max_num_iterations = iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &ceres_problem, &summary);
  return summary.termination_type == ceres::CONVERGENCE ||
         summary.termination_type == ceres::NO_CONVERGENCE;
}

void ClassifyOutliers(const BundleAdjustmentProblem& problem, const std::vector<double>& cameras,
                      const std::vector<double>& points, std::vector<bool>& outlier) {
  std::vector<Rigid3d> poses(problem.cameras.size());
  for (size_t c = 0; c < poses.size(); ++c) poses[c] = internal::ParamsToRigid(&cameras[6 * c]);
  for (size_t i = 0; i < problem.observations.size(); ++i) {
    const BaObservation& o = problem.observations[i];
    const Eigen::Vector3d point(points[3 * o.point], points[3 * o.point + 1],
                                points[3 * o.point + 2]);
    double depth = 0;
    const double chi2 =
        internal::ObservationChi2(problem.intrinsics, o.image, poses[o.camera], point, &depth);
    outlier[i] = depth <= 0 || chi2 > (o.image.HasDepth() ? kChi2Stereo : kChi2Mono);
  }
}

}  // namespace

BundleAdjustmentResult SolveBundleAdjustment(const BundleAdjustmentProblem& problem,
                                             const BundleAdjustmentOptions& options) {
  options.Check();
  for (const BaObservation& o : problem.observations) {
    if (o.camera >= problem.cameras.size() || o.point >= problem.points.size()) {
      throw std::invalid_argument("bundle adjustment: observation index out of range");
    }
  }
  std::vector<double> cameras(6 * problem.cameras.size()), points(3 * problem.points.size());
  for (size_t c = 0; c < problem.cameras.size(); ++c) {
    internal::RigidToParams(problem.cameras[c].cam_from_world, &cameras[6 * c]);
  }
  for (size_t p = 0; p < problem.points.size(); ++p) {
    for (int k = 0; k < 3; ++k) points[3 * p + k] = problem.points[p][k];
  }

  BundleAdjustmentResult result;
  result.outlier.assign(problem.observations.size(), false);
  result.converged = Solve(problem, result.outlier, options.first_iterations, cameras, points);
  ClassifyOutliers(problem, cameras, points, result.outlier);
  if (options.second_iterations > 0) {
    result.converged = Solve(problem, result.outlier, options.second_iterations, cameras, points);
    ClassifyOutliers(problem, cameras, points, result.outlier);
  }

  result.cam_from_world.resize(problem.cameras.size());
  for (size_t c = 0; c < problem.cameras.size(); ++c) {
    result.cam_from_world[c] = problem.cameras[c].fixed ? problem.cameras[c].cam_from_world
                                                        : internal::ParamsToRigid(&cameras[6 * c]);
  }
  result.points.resize(problem.points.size());
  for (size_t p = 0; p < problem.points.size(); ++p) {
    result.points[p] = Eigen::Vector3d(points[3 * p], points[3 * p + 1], points[3 * p + 2]);
  }
  return result;
}

}  // namespace ademono
