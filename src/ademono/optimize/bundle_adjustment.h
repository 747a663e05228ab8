#pragma once
// Local bundle adjustment (ORB-SLAM's LocalBundleAdjustment) with Ceres: free keyframe poses and
// points, fixed border keyframes, Huber loss, a first solve, outlier classification by chi2 (and
// points behind the camera), then a second solve without the outliers. Single-threaded, with
// parameter blocks added in the given order, so results are identical run to run.

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "ademono/optimize/optimizer_types.h"

namespace ademono {

template <typename Options>
class OptionsTable;

// Ceres' linear solver for the Schur-complemented normal equations (see docs/performance.md for
// the measured trade-off).
enum class BaLinearSolver { kSparseSchur, kDenseSchur, kIterativeSchur };

// Who solves: the built-in Levenberg-Marquardt on a dense Schur complement (optimize/schur_lm.h:
// Ceres' iteration at about a fifth of its cost on a local window), or Ceres with
// `linear_solver`. The dense reduced system suits windows, so a problem with more than
// kMaxLmFreeCameras free cameras goes to Ceres whatever the choice.
enum class BaSolver { kLm, kCeres };

struct BundleAdjustmentOptions {
  int first_iterations = 5;
  int second_iterations = 10;
  bool analytic_jacobians = true;  // false: Ceres auto-diff (the reference the tests compare to)
  BaLinearSolver linear_solver = BaLinearSolver::kSparseSchur;
  BaSolver solver = BaSolver::kLm;
  static constexpr size_t kMaxLmFreeCameras = 64;
  void Check() const;  // throws std::invalid_argument
  // Its keys in the flat `mapping:` node: ba_first_iterations, ba_second_iterations,
  // ba_jacobians (analytic|autodiff, Ceres only), ba_solver (lm|ceres), ba_linear_solver
  // (sparse_schur|dense_schur|iterative_schur, Ceres only).
  // Ceres runs on one thread: with 2 its sums are ordered differently and results are no longer
  // byte-identical (measured, docs/performance.md).
  static const OptionsTable<BundleAdjustmentOptions>& Table();
  bool operator==(const BundleAdjustmentOptions&) const = default;
};

struct BaCamera {
  Rigid3d cam_from_world = Rigid3d::Identity();
  bool fixed = false;
};

struct BaObservation {
  size_t camera = 0;  // index into cameras
  size_t point = 0;   // index into points
  ImageObservation image;
};

// A point on a plane of known distance from a camera (the road under a vehicle's camera, at the
// rig's height): residual inv_sigma * (normal . (R X + t) - distance), Huber at one sigma. This
// is how a known camera height holds the local map's scale in every window, where a global
// rescale cannot undo drift (docs/slam.md "Scale from the camera height").
struct BaPlaneDistance {
  size_t camera = 0;
  size_t point = 0;
  Eigen::Vector3d normal_cam = Eigen::Vector3d(0, -1, 0);  // unit, in the camera's frame
  // normal . X_cam the point should have (minus the camera height, for a road point and a
  // normal pointing from the road to the camera)
  double distance = 0.0;
  double inv_sigma = 1.0;
  // Distances of one camera with the same `plane` >= 0 share one normal, solved for on the unit
  // sphere from `normal_cam` (the first of them): the points decide the plane's tilt, the known
  // distance only the scale. -1: the normal is held as given.
  int plane = -1;
};

struct BundleAdjustmentProblem {
  PinholeIntrinsics intrinsics;
  std::vector<BaCamera> cameras;
  std::vector<Eigen::Vector3d> points;  // world
  // Per point: held fixed (a loaded map's point in localisation only); empty: every point free.
  std::vector<uint8_t> point_fixed;
  std::vector<BaObservation> observations;
  std::vector<BaPlaneDistance> plane_distances;  // not part of the recorded problem files
};

struct BundleAdjustmentResult {
  std::vector<Rigid3d> cam_from_world;  // one per camera (fixed ones unchanged)
  std::vector<Eigen::Vector3d> points;
  std::vector<bool> outlier;  // one per observation, after the second solve
  bool converged = false;
};

// Throws std::invalid_argument for indices out of range.
BundleAdjustmentResult SolveBundleAdjustment(const BundleAdjustmentProblem& problem,
                                             const BundleAdjustmentOptions& options = {});

// Calls `observer` with every problem SolveBundleAdjustment is given, before solving (null: none).
// For recording real problems (bench/ba_bench.cpp --record); not meant for production runs.
void SetBundleAdjustmentObserver(std::function<void(const BundleAdjustmentProblem&)> observer);

// A problem in a compact little-endian binary file (the benchmark's recorded seq-a problem).
// Read throws std::runtime_error naming the file on a missing, truncated or malformed file.
void WriteBundleAdjustmentProblem(const BundleAdjustmentProblem& problem, const std::string& path);
BundleAdjustmentProblem ReadBundleAdjustmentProblem(const std::string& path);

}  // namespace ademono
