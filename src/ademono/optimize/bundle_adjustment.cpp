#include "ademono/optimize/bundle_adjustment.h"

#include <spdlog/spdlog.h>

#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <stdexcept>

#include "ademono/core/options_table.h"
#include "ademono/optimize/residuals.h"
#include "ademono/optimize/schur_lm.h"

namespace ademono {

const OptionsTable<BundleAdjustmentOptions>& BundleAdjustmentOptions::Table() {
  using B = BundleAdjustmentOptions;
  static const auto table =
      OptionsTable<B>("mapping")
          .Add("ba_first_iterations", &B::first_iterations, Range::AtLeast(1))
          .Add("ba_second_iterations", &B::second_iterations, Range::AtLeast(0))
          .AddChoice<bool>("ba_jacobians", &B::analytic_jacobians,
                           {{"analytic", true}, {"autodiff", false}})
          .AddChoice<BaSolver>("ba_solver", &B::solver,
                               {{"lm", BaSolver::kLm}, {"ceres", BaSolver::kCeres}})
          .AddChoice<BaLinearSolver>("ba_linear_solver", &B::linear_solver,
                                     {{"sparse_schur", BaLinearSolver::kSparseSchur},
                                      {"dense_schur", BaLinearSolver::kDenseSchur},
                                      {"iterative_schur", BaLinearSolver::kIterativeSchur}});
  return table;
}

void BundleAdjustmentOptions::Check() const {
  Table().CheckRanges(*this);
  if (!analytic_jacobians && solver == BaSolver::kLm)
    throw std::invalid_argument("mapping.ba_jacobians: autodiff needs mapping.ba_solver: ceres");
}

namespace {

std::mutex observer_mutex;
std::function<void(const BundleAdjustmentProblem&)>& Observer() {
  static std::function<void(const BundleAdjustmentProblem&)> observer;
  return observer;
}

template <int kDim>
ceres::CostFunction* MakeCost(const BundleAdjustmentOptions& options,
                              const PinholeIntrinsics& intrinsics, const ImageObservation& image) {
  if (options.analytic_jacobians) return new internal::AnalyticBaCost<kDim>(intrinsics, image);
  return new ceres::AutoDiffCostFunction<internal::BaResidual<kDim>, kDim, 6, 3>(
      new internal::BaResidual<kDim>(intrinsics, image));
}

struct PlaneDistanceResidual {
  explicit PlaneDistanceResidual(const BaPlaneDistance& d) : d(d) {}
  template <typename T>
  bool operator()(const T* camera, const T* point, T* residual) const {
    const T normal[3] = {T(d.normal_cam[0]), T(d.normal_cam[1]), T(d.normal_cam[2])};
    return Along(camera, point, normal, residual);
  }
  template <typename T>
  bool operator()(const T* camera, const T* point, const T* normal, T* residual) const {
    return Along(camera, point, normal, residual);
  }
  template <typename T>
  bool Along(const T* camera, const T* point, const T* normal, T* residual) const {
    T q[3];
    ceres::AngleAxisRotatePoint(camera, point, q);
    T along = T(0);
    for (int k = 0; k < 3; ++k) along += normal[k] * (q[k] + camera[3 + k]);
    residual[0] = T(d.inv_sigma) * (along - T(d.distance));
    return true;
  }
  BaPlaneDistance d;
};

// Solves with the observations not flagged in `skip`; returns whether Ceres converged.
bool SolveWithCeres(const BundleAdjustmentProblem& problem, const BundleAdjustmentOptions& ba,
                    const std::vector<bool>& skip, int iterations, std::vector<double>& cameras,
                    std::vector<double>& points, double* normals,
                    const std::vector<size_t>& normal_slot) {
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
      ceres_problem.AddResidualBlock(MakeCost<3>(ba, problem.intrinsics, o.image),
                                     new ceres::HuberLoss(std::sqrt(kChi2Stereo)), camera, point);
    } else {
      ceres_problem.AddResidualBlock(MakeCost<2>(ba, problem.intrinsics, o.image),
                                     new ceres::HuberLoss(std::sqrt(kChi2Mono)), camera, point);
    }
    point_used[o.point] = true;
    camera_used[o.camera] = true;
  }
  if (ceres_problem.NumResidualBlocks() == 0) return false;
  // Only on points and cameras the observations keep: the plane never holds an outlier's point.
  for (size_t i = 0; i < problem.plane_distances.size(); ++i) {
    const BaPlaneDistance& d = problem.plane_distances[i];
    if (!point_used[d.point] || !camera_used[d.camera]) continue;
    if (d.plane < 0) {
      ceres_problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<PlaneDistanceResidual, 1, 6, 3>(
              new PlaneDistanceResidual(d)),
          new ceres::HuberLoss(1.0), &cameras[6 * d.camera], &points[3 * d.point]);
      continue;
    }
    double* normal = normals + 3 * normal_slot[i];
    ceres_problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<PlaneDistanceResidual, 1, 6, 3, 3>(
            new PlaneDistanceResidual(d)),
        new ceres::HuberLoss(1.0), &cameras[6 * d.camera], &points[3 * d.point], normal);
    if (!ceres_problem.HasManifold(normal)) {
      ceres_problem.SetManifold(normal, new ceres::SphereManifold<3>());
      ordering->AddElementToGroup(normal, 1);
    }
  }
  for (size_t c = 0; c < problem.cameras.size(); ++c) {
    if (!camera_used[c]) continue;
    if (problem.cameras[c].fixed) ceres_problem.SetParameterBlockConstant(&cameras[6 * c]);
    ordering->AddElementToGroup(&cameras[6 * c], 1);
  }
  for (size_t p = 0; p < problem.points.size(); ++p) {
    if (!point_used[p]) continue;
    if (p < problem.point_fixed.size() && problem.point_fixed[p])
      ceres_problem.SetParameterBlockConstant(&points[3 * p]);
    ordering->AddElementToGroup(&points[3 * p], 0);
  }

  ceres::Solver::Options options;
  switch (ba.linear_solver) {
    case BaLinearSolver::kSparseSchur:
      options.linear_solver_type = ceres::SPARSE_SCHUR;
      break;
    case BaLinearSolver::kDenseSchur:
      options.linear_solver_type = ceres::DENSE_SCHUR;
      break;
    case BaLinearSolver::kIterativeSchur:
      options.linear_solver_type = ceres::ITERATIVE_SCHUR;
      options.preconditioner_type = ceres::SCHUR_JACOBI;
      break;
  }
  options.linear_solver_ordering = ordering;
  options.max_num_iterations = iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &ceres_problem, &summary);
  spdlog::debug("BA solve: {} iterations, {} residuals, {:.1f} ms (linear {:.1f}, eval {:.1f}), {}",
                summary.iterations.size(), summary.num_residual_blocks,
                1e3 * summary.total_time_in_seconds, 1e3 * summary.linear_solver_time_in_seconds,
                1e3 * (summary.residual_evaluation_time_in_seconds +
                       summary.jacobian_evaluation_time_in_seconds),
                summary.message);
  return summary.termination_type == ceres::CONVERGENCE ||
         summary.termination_type == ceres::NO_CONVERGENCE;
}

bool Solve(const BundleAdjustmentProblem& problem, const BundleAdjustmentOptions& ba,
           const std::vector<bool>& skip, int iterations, std::vector<double>& cameras,
           std::vector<double>& points, double* normals, const std::vector<size_t>& normal_slot) {
  size_t free_cameras = 0;
  for (const BaCamera& c : problem.cameras) free_cameras += c.fixed ? 0 : 1;
  if (ba.solver == BaSolver::kLm && free_cameras <= BundleAdjustmentOptions::kMaxLmFreeCameras) {
    return internal::SolveSchurLm(problem, skip, iterations, cameras, points, normals, normal_slot);
  }
  return SolveWithCeres(problem, ba, skip, iterations, cameras, points, normals, normal_slot);
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
  {
    std::lock_guard<std::mutex> lock(observer_mutex);
    if (Observer()) Observer()(problem);
  }
  for (const BaObservation& o : problem.observations) {
    if (o.camera >= problem.cameras.size() || o.point >= problem.points.size()) {
      throw std::invalid_argument("bundle adjustment: observation index out of range");
    }
  }
  for (const BaPlaneDistance& d : problem.plane_distances) {
    if (d.camera >= problem.cameras.size() || d.point >= problem.points.size()) {
      throw std::invalid_argument("bundle adjustment: plane distance index out of range");
    }
  }
  // One solved normal per (camera, plane), started from its first distance's; normal_slot[i] is
  // distance i's (unused for held normals).
  std::vector<size_t> normal_slot(problem.plane_distances.size());
  std::map<std::pair<size_t, int>, size_t> slot_of;
  std::vector<Eigen::Vector3d> initial_normals;
  for (size_t i = 0; i < problem.plane_distances.size(); ++i) {
    const BaPlaneDistance& d = problem.plane_distances[i];
    if (d.plane < 0) continue;
    const auto [it, inserted] = slot_of.emplace(std::make_pair(d.camera, d.plane), slot_of.size());
    normal_slot[i] = it->second;
    if (inserted) initial_normals.push_back(d.normal_cam.normalized());
  }
  // The normals live behind the cameras in one buffer: Ceres orders a group's parameter blocks by
  // address, so two buffers would put cameras and normals in whichever order the heap gave them,
  // and the solve's rounding would change from run to run.
  const size_t camera_values = 6 * problem.cameras.size();
  std::vector<double> cameras(camera_values + 3 * initial_normals.size()),
      points(3 * problem.points.size());
  for (size_t c = 0; c < problem.cameras.size(); ++c) {
    internal::RigidToParams(problem.cameras[c].cam_from_world, &cameras[6 * c]);
  }
  for (size_t p = 0; p < problem.points.size(); ++p) {
    for (int k = 0; k < 3; ++k) points[3 * p + k] = problem.points[p][k];
  }
  double* normals = cameras.data() + camera_values;
  for (size_t n = 0; n < initial_normals.size(); ++n) {
    for (int k = 0; k < 3; ++k) normals[3 * n + k] = initial_normals[n][k];
  }

  BundleAdjustmentResult result;
  result.outlier.assign(problem.observations.size(), false);
  result.converged = Solve(problem, options, result.outlier, options.first_iterations, cameras,
                           points, normals, normal_slot);
  ClassifyOutliers(problem, cameras, points, result.outlier);
  if (options.second_iterations > 0) {
    result.converged = Solve(problem, options, result.outlier, options.second_iterations, cameras,
                             points, normals, normal_slot);
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

void SetBundleAdjustmentObserver(std::function<void(const BundleAdjustmentProblem&)> observer) {
  std::lock_guard<std::mutex> lock(observer_mutex);
  Observer() = std::move(observer);
}

// File layout: magic "ADEMOBA1", intrinsics (5 doubles), then counts (3 uint64) and the cameras
// (fixed byte, 12 doubles: rotation row-major, translation), points (3 doubles) and observations
// (camera, point as uint32; u, v, u_right, inv_sigma2, depth_inv_sigma as doubles).
namespace {
constexpr char kMagic[8] = {'A', 'D', 'E', 'M', 'O', 'B', 'A', '1'};

template <typename T>
void Put(std::ofstream& out, T value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
T Get(std::ifstream& in, const std::string& path) {
  T value;
  if (!in.read(reinterpret_cast<char*>(&value), sizeof(T)))
    throw std::runtime_error(path + ": truncated bundle adjustment problem");
  return value;
}
}  // namespace

void WriteBundleAdjustmentProblem(const BundleAdjustmentProblem& problem, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error(path + ": cannot open for writing");
  out.write(kMagic, sizeof(kMagic));
  const PinholeIntrinsics& k = problem.intrinsics;
  for (double v : {k.fx, k.fy, k.cx, k.cy, k.bf}) Put(out, v);
  Put<uint64_t>(out, problem.cameras.size());
  Put<uint64_t>(out, problem.points.size());
  Put<uint64_t>(out, problem.observations.size());
  for (const BaCamera& c : problem.cameras) {
    Put<uint8_t>(out, c.fixed ? 1 : 0);
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 3; ++col) Put(out, c.cam_from_world.linear()(r, col));
    for (int i = 0; i < 3; ++i) Put(out, c.cam_from_world.translation()[i]);
  }
  for (const Eigen::Vector3d& p : problem.points)
    for (int i = 0; i < 3; ++i) Put(out, p[i]);
  for (const BaObservation& o : problem.observations) {
    Put<uint32_t>(out, static_cast<uint32_t>(o.camera));
    Put<uint32_t>(out, static_cast<uint32_t>(o.point));
    for (double v : {o.image.pixel.x(), o.image.pixel.y(), o.image.u_right, o.image.inv_sigma2,
                     o.image.depth_inv_sigma})
      Put(out, v);
  }
  if (!out) throw std::runtime_error(path + ": write failed");
}

BundleAdjustmentProblem ReadBundleAdjustmentProblem(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open bundle adjustment problem");
  char magic[sizeof(kMagic)];
  if (!in.read(magic, sizeof(magic)) || std::memcmp(magic, kMagic, sizeof(kMagic)) != 0)
    throw std::runtime_error(path + ": not a bundle adjustment problem (bad magic)");
  BundleAdjustmentProblem problem;
  PinholeIntrinsics& k = problem.intrinsics;
  for (double* v : {&k.fx, &k.fy, &k.cx, &k.cy, &k.bf}) *v = Get<double>(in, path);
  const auto num_cameras = Get<uint64_t>(in, path), num_points = Get<uint64_t>(in, path),
             num_observations = Get<uint64_t>(in, path);
  // Sizes bounded by what the file can hold, so a corrupt count cannot allocate wildly.
  constexpr uint64_t kLimit = uint64_t{1} << 26;
  if (num_cameras > kLimit || num_points > kLimit || num_observations > kLimit)
    throw std::runtime_error(path + ": implausible bundle adjustment problem size");
  problem.cameras.resize(num_cameras);
  for (BaCamera& c : problem.cameras) {
    c.fixed = Get<uint8_t>(in, path) != 0;
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 3; ++col) c.cam_from_world.linear()(r, col) = Get<double>(in, path);
    for (int i = 0; i < 3; ++i) c.cam_from_world.translation()[i] = Get<double>(in, path);
  }
  problem.points.resize(num_points);
  for (Eigen::Vector3d& p : problem.points)
    for (int i = 0; i < 3; ++i) p[i] = Get<double>(in, path);
  problem.observations.resize(num_observations);
  for (BaObservation& o : problem.observations) {
    o.camera = Get<uint32_t>(in, path);
    o.point = Get<uint32_t>(in, path);
    if (o.camera >= num_cameras || o.point >= num_points)
      throw std::runtime_error(path + ": observation index out of range");
    for (double* v : {&o.image.pixel.x(), &o.image.pixel.y(), &o.image.u_right, &o.image.inv_sigma2,
                      &o.image.depth_inv_sigma})
      *v = Get<double>(in, path);
  }
  if (in.peek() != std::char_traits<char>::eof())
    throw std::runtime_error(path + ": trailing bytes after the bundle adjustment problem");
  return problem;
}

}  // namespace ademono
