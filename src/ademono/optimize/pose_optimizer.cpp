#include "ademono/optimize/pose_optimizer.h"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <type_traits>

#include "ademono/core/options_table.h"
#include "ademono/optimize/residuals.h"
#include "ademono/optimize/trust_region.h"

namespace ademono {

const OptionsTable<PoseOptimizerOptions>& PoseOptimizerOptions::Table() {
  using P = PoseOptimizerOptions;
  static const auto table =
      OptionsTable<P>("optimizer")
          .Add("pose_rounds", &P::rounds, Range::AtLeast(1))
          .Add("pose_iterations_per_round", &P::iterations_per_round, Range::AtLeast(1))
          .AddChoice<bool>("pose_jacobians", &P::analytic_jacobians,
                           {{"analytic", true}, {"autodiff", false}})
          .AddChoice<bool>("pose_solver", &P::use_ceres, {{"lm", false}, {"ceres", true}});
  return table;
}

void PoseOptimizerOptions::Check() const {
  Table().CheckRanges(*this);
  if (!analytic_jacobians && !use_ceres)
    throw std::invalid_argument(
        "optimizer.pose_jacobians: autodiff needs optimizer.pose_solver: ceres");
}

namespace {
template <int kDim>
ceres::CostFunction* MakeCost(bool analytic, const PinholeIntrinsics& intrinsics,
                              const PoseObservation& o) {
  if (analytic) return new internal::AnalyticPoseCost<kDim>(intrinsics, o.image, o.point_world);
  return new ceres::AutoDiffCostFunction<internal::PoseOnlyResidual<kDim>, kDim, 6>(
      new internal::PoseOnlyResidual<kDim>(intrinsics, o.image, o.point_world));
}

// One round's problem for the built-in solver: the active observations' residuals.
struct LmProblem {
  std::vector<internal::ProjectionResidual<3>> depth;
  std::vector<Eigen::Vector3d> depth_points;
  std::vector<internal::ProjectionResidual<2>> mono;
  std::vector<Eigen::Vector3d> mono_points;
  bool robust = true;
};

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

// Huber (trust_region.h) in the robust rounds, plain squares in the last.
inline double Huber(double s, double a2, bool robust, double* rho1) {
  if (robust) return internal::HuberRho(s, a2, rho1);
  *rho1 = 1.0;
  return s;
}

// 1/2 sum rho(|r|^2) at `camera`; with h and g also J^T W J and J^T W r (W = rho').
double LmEvaluate(const LmProblem& p, const double* camera, Matrix6* h, Vector6* g) {
  double cost = 0;
  std::optional<internal::CameraRotation> rotation;  // one camera: its rotation once
  if (h != nullptr) {
    h->setZero();
    g->setZero();
    rotation.emplace(camera);
  }
  auto add = [&](const auto& residuals, const std::vector<Eigen::Vector3d>& points, double a2) {
    constexpr int kDim = std::decay_t<decltype(residuals[0])>::kDimension;
    for (size_t i = 0; i < residuals.size(); ++i) {
      Eigen::Matrix<double, kDim, 1> r;
      Eigen::Matrix<double, kDim, 6, Eigen::RowMajor> j;
      internal::EvaluateProjection<kDim>(residuals[i], camera, points[i].data(), r.data(),
                                         h != nullptr ? j.data() : nullptr, nullptr,
                                         rotation ? &*rotation : nullptr);
      double rho1 = 1;
      cost += 0.5 * Huber(r.squaredNorm(), a2, p.robust, &rho1);
      if (h != nullptr) {
        h->noalias() += rho1 * j.transpose() * j;
        g->noalias() += rho1 * j.transpose() * r;
      }
    }
  };
  add(p.depth, p.depth_points, kChi2Stereo);
  add(p.mono, p.mono_points, kChi2Mono);
  return cost;
}

// Levenberg-Marquardt as Ceres' TrustRegionMinimizer with its defaults (trust_region.h), at most
// `max_iterations` steps.
void LmSolve(const LmProblem& p, double* camera, int max_iterations) {
  Matrix6 h;
  Vector6 g;
  double cost = LmEvaluate(p, camera, &h, &g);
  internal::LmTrustRegion region;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    if (g.cwiseAbs().maxCoeff() <= internal::kLmGradientTolerance) return;
    // Jacobi scaling of the columns: 1 / (1 + |J_col|).
    Vector6 scale;
    for (int c = 0; c < 6; ++c) scale[c] = 1.0 / (1.0 + std::sqrt(h(c, c)));
    const Matrix6 hs = scale.asDiagonal() * h * scale.asDiagonal();
    const Vector6 gs = scale.cwiseProduct(g);
    Matrix6 a = hs;
    for (int c = 0; c < 6; ++c)
      a(c, c) += std::clamp(hs(c, c), internal::kLmMinDiagonal, internal::kLmMaxDiagonal) /
                 region.Radius();
    const Vector6 step_scaled = -a.ldlt().solve(gs);
    const Vector6 step = scale.cwiseProduct(step_scaled);
    const Eigen::Map<const Vector6> x(camera);
    if (!step.allFinite()) {
      region.Rejected();
      continue;
    }
    // Model decrease of the Gauss-Newton model (not the damped one), as Ceres.
    const double model_decrease = -(g.dot(step) + 0.5 * step.dot(h * step));
    if (step.norm() <=
        internal::kLmParameterTolerance * (x.norm() + internal::kLmParameterTolerance))
      return;
    Vector6 candidate = x + step;
    const double new_cost = LmEvaluate(p, candidate.data(), nullptr, nullptr);
    // Function tolerance: a change below 1e-6 of the cost ends the solve (candidate not taken).
    if (std::isfinite(new_cost) &&
        std::abs(cost - new_cost) <= internal::kLmFunctionTolerance * cost)
      return;
    const double quality = model_decrease > 0 ? (cost - new_cost) / model_decrease : -1.0;
    if (std::isfinite(new_cost) && quality > internal::kLmMinRelativeDecrease) {
      std::copy(candidate.data(), candidate.data() + 6, camera);
      cost = LmEvaluate(p, camera, &h, &g);
      region.Accepted(quality);
    } else {
      region.Rejected();
      if (region.Collapsed()) return;
    }
  }
}

// One round with Ceres over the observations not marked outliers; false: fewer than 3 of them.
bool SolveRoundCeres(const PinholeIntrinsics& intrinsics,
                     const std::vector<PoseObservation>& observations,
                     const std::vector<bool>& outlier, bool robust,
                     const PoseOptimizerOptions& options, double* camera) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.iterations_per_round;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  ceres::Problem problem;
  int added = 0;
  for (size_t i = 0; i < observations.size(); ++i) {
    if (outlier[i]) continue;
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
  if (added < 3) return false;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  return true;
}

// The same round with the built-in Levenberg-Marquardt.
bool SolveRoundLm(const PinholeIntrinsics& intrinsics,
                  const std::vector<PoseObservation>& observations,
                  const std::vector<bool>& outlier, bool robust,
                  const PoseOptimizerOptions& options, double* camera) {
  LmProblem lm;
  lm.robust = robust;
  for (size_t i = 0; i < observations.size(); ++i) {
    if (outlier[i]) continue;
    const PoseObservation& o = observations[i];
    if (o.image.HasDepth()) {
      lm.depth.emplace_back(intrinsics, o.image);
      lm.depth_points.push_back(o.point_world);
    } else {
      lm.mono.emplace_back(intrinsics, o.image);
      lm.mono_points.push_back(o.point_world);
    }
  }
  if (lm.depth.size() + lm.mono.size() < 3) return false;
  LmSolve(lm, camera, options.iterations_per_round);
  return true;
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
  for (int round = 0; round < options.rounds; ++round) {
    // ORB-SLAM keeps the robust kernel for the first two rounds only: by then the outliers are
    // out and the plain least squares gives the best estimate for the inliers.
    const bool robust = round < 2 || options.robust_last_round;
    const bool solved =
        options.use_ceres
            ? SolveRoundCeres(intrinsics, observations, result.outlier, robust, options, camera)
            : SolveRoundLm(intrinsics, observations, result.outlier, robust, options, camera);
    if (!solved) break;

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
