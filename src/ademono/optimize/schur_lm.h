#pragma once
// Levenberg-Marquardt for bundle adjustment with the points eliminated into a dense reduced
// system (the Schur complement): the shape of a local BA window, a few dozen free cameras (and
// road normals) and thousands of points. Ceres solves the same problem through a residual-block
// object per observation and a sparse reduced matrix addressed through hash maps, which costs
// about five times the arithmetic here (bench/ba_bench.cpp: 21 against 106 ms a window;
// docs/performance.md).
//
// The iteration is Ceres' LM step by step, so the two agree to the solver's tolerances and a
// test compares them: Jacobi scaling from the first Jacobian, the LM diagonal clamped to
// [1e-6, 1e32] in scaled units, radius 1e4 updated by the gain ratio, Huber as Ceres' corrector
// (residual and Jacobian scaled by sqrt(rho')), function/parameter/gradient tolerances 1e-6,
// 1e-8, 1e-10, at most 5 invalid steps in a row. A reduced system that is not positive definite
// is an invalid step, as Ceres' failed Cholesky is. Sums run in a fixed order: deterministic.
#include <cstddef>
#include <vector>

#include "ademono/optimize/bundle_adjustment.h"

namespace ademono::internal {

// Solves `problem` without the observations flagged in `skip`, in place: cameras (6 each:
// angle-axis, translation), the shared road normals (3 each, on the unit sphere) at `normals`,
// normal_slot[i] being plane distance i's, and points (3 each). A plane distance counts only
// while some kept observation uses its camera and its point (as the Ceres path). Returns false
// when nothing is left to solve, the start is not finite or 5 steps in a row were invalid (as
// Ceres' FAILURE); the parameters are then the last accepted ones.
bool SolveSchurLm(const BundleAdjustmentProblem& problem, const std::vector<bool>& skip,
                  int max_iterations, std::vector<double>& cameras, std::vector<double>& points,
                  double* normals, const std::vector<size_t>& normal_slot);

}  // namespace ademono::internal
