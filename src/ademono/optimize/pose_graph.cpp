#include "ademono/optimize/pose_graph.h"

#include <ceres/ceres.h>

#include <cmath>
#include <stdexcept>

namespace ademono {

Sim3d Sim3d::FromRigid(const Rigid3d& rigid) {
  Sim3d s;
  s.rotation = Eigen::Quaterniond(rigid.linear()).normalized();
  s.translation = rigid.translation();
  return s;
}

Sim3d Sim3d::Inverse() const {
  Sim3d inv;
  inv.scale = 1.0 / scale;
  inv.rotation = rotation.conjugate();
  inv.translation = -(inv.scale * (inv.rotation * translation));
  return inv;
}

Sim3d Sim3d::operator*(const Sim3d& other) const {
  Sim3d out;
  out.scale = scale * other.scale;
  out.rotation = (rotation * other.rotation).normalized();
  out.translation = scale * (rotation * other.translation) + translation;
  return out;
}

Rigid3d Sim3d::ToRigid() const {
  Rigid3d rigid = Rigid3d::Identity();
  rigid.linear() = rotation.toRotationMatrix();
  rigid.translation() = translation / scale;
  return rigid;
}

namespace {

// Residual of an edge: the similarity E = measured^-1 * (g_i * g_j^-1), which is the identity for
// a perfect fit, as (2 * vec(q_E), t_E, log s_E). Per vertex: quaternion (x, y, z, w, Eigen
// order), translation, log scale.
struct Sim3EdgeCost {
  Sim3EdgeCost(const Sim3d& measured, const Eigen::Matrix<double, 7, 1>& w) : weight(w) {
    const Sim3d inv = measured.Inverse();
    inv_scale = inv.scale;
    inv_rotation = inv.rotation;
    inv_translation = inv.translation;
  }
  template <typename T>
  bool operator()(const T* qi, const T* ti, const T* li, const T* qj, const T* tj, const T* lj,
                  T* residual) const {
    using Quat = Eigen::Quaternion<T>;
    using Vec3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Quat> Ri(qi), Rj(qj);
    const Eigen::Map<const Vec3> Ti(ti), Tj(tj);
    // g_i * g_j^-1 = (s_i / s_j, R_i R_j^T, t_i - (s_i / s_j) R_i R_j^T t_j)
    const T ratio = ceres::exp(li[0] - lj[0]);
    const Quat Rij = Ri * Rj.conjugate();
    const Vec3 tij = Ti - ratio * (Rij * Tj);
    // E = inv * (g_i g_j^-1): rotation inv_R * Rij, translation inv_s * inv_R * tij + inv_t
    const Quat Rm = inv_rotation.cast<T>();
    const Quat Re = Rm * Rij;
    const Vec3 te = T(inv_scale) * (Rm * tij) + inv_translation.cast<T>();
    // The quaternion's sign is arbitrary: take the one with w >= 0 so small errors stay small.
    const T sign = Re.w() < T(0) ? T(-1) : T(1);
    residual[0] = T(2) * sign * Re.x();
    residual[1] = T(2) * sign * Re.y();
    residual[2] = T(2) * sign * Re.z();
    residual[3] = te.x();
    residual[4] = te.y();
    residual[5] = te.z();
    residual[6] = li[0] - lj[0] + T(std::log(inv_scale));
    for (int k = 0; k < 7; ++k) residual[k] *= T(weight[k]);
    return true;
  }
  Eigen::Matrix<double, 7, 1> weight;
  double inv_scale = 1;
  Eigen::Quaterniond inv_rotation;
  Eigen::Vector3d inv_translation;
};

// Reprojection of a source point into the target (forward: x_b = s R x_a + t) or, inverted, of a
// target point into the source (x_a = R^T (x_b - t) / s).
struct Sim3ReprojectionCost {
  Sim3ReprojectionCost(const Sim3Observation& o, const PinholeIntrinsics& in, bool inverse)
      : obs(o), intrinsics(in), inverse(inverse) {}
  template <typename T>
  bool operator()(const T* q, const T* t, const T* log_s, T* residual) const {
    using Vec3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Eigen::Quaternion<T>> R(q);
    const Eigen::Map<const Vec3> tr(t);
    const T s = ceres::exp(log_s[0]);
    const Vec3 x = obs.point.cast<T>();
    const Vec3 y = inverse ? Vec3((R.conjugate() * (x - tr)) / s) : Vec3(s * (R * x) + tr);
    if (y.z() <= T(1e-6)) {
      residual[0] = residual[1] = T(0);
      return true;
    }
    const T w = T(std::sqrt(obs.inv_sigma2));
    residual[0] = w * (T(intrinsics.fx) * y.x() / y.z() + T(intrinsics.cx) - T(obs.pixel.x()));
    residual[1] = w * (T(intrinsics.fy) * y.y() / y.z() + T(intrinsics.cy) - T(obs.pixel.y()));
    return true;
  }
  Sim3Observation obs;
  PinholeIntrinsics intrinsics;
  bool inverse;
};

}  // namespace

Sim3d RefineSim3(const Sim3d& b_from_a, const PinholeIntrinsics& intrinsics_a,
                 const PinholeIntrinsics& intrinsics_b, const std::vector<Sim3Observation>& in_b,
                 const std::vector<Sim3Observation>& in_a, bool fix_scale, int iterations) {
  Eigen::Vector4d q = b_from_a.rotation.normalized().coeffs();
  Eigen::Vector3d t = b_from_a.translation;
  double log_s = std::log(b_from_a.scale);
  ceres::Problem problem;
  problem.AddParameterBlock(q.data(), 4, new ceres::EigenQuaternionManifold());
  problem.AddParameterBlock(t.data(), 3);
  problem.AddParameterBlock(&log_s, 1);
  for (const Sim3Observation& o : in_b) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<Sim3ReprojectionCost, 2, 4, 3, 1>(
            new Sim3ReprojectionCost(o, intrinsics_b, false)),
        new ceres::HuberLoss(std::sqrt(5.991)), q.data(), t.data(), &log_s);
  }
  for (const Sim3Observation& o : in_a) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<Sim3ReprojectionCost, 2, 4, 3, 1>(
            new Sim3ReprojectionCost(o, intrinsics_a, true)),
        new ceres::HuberLoss(std::sqrt(5.991)), q.data(), t.data(), &log_s);
  }
  if (fix_scale) problem.SetParameterBlockConstant(&log_s);
  if (problem.NumResidualBlocks() > 0) {
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = iterations;
    options.num_threads = 1;
    options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
  }
  Sim3d out;
  out.rotation = Eigen::Quaterniond(q.data()).normalized();
  out.translation = t;
  out.scale = std::exp(log_s);
  return out;
}

PoseGraphResult SolvePoseGraph(const PoseGraphProblem& problem) {
  const size_t n = problem.cam_from_world.size();
  if (problem.fixed.size() != n) throw std::invalid_argument("pose graph: fixed size mismatch");
  for (const PoseGraphEdge& e : problem.edges) {
    if (e.i >= n || e.j >= n || e.i == e.j)
      throw std::invalid_argument("pose graph: bad edge vertex index");
  }
  std::vector<Eigen::Vector4d> q(n);
  std::vector<Eigen::Vector3d> t(n);
  std::vector<double> log_s(n);
  for (size_t k = 0; k < n; ++k) {
    const Sim3d& g = problem.cam_from_world[k];
    q[k] = g.rotation.normalized().coeffs();
    t[k] = g.translation;
    log_s[k] = std::log(g.scale);
  }
  ceres::Problem ceres_problem;
  for (size_t k = 0; k < n; ++k) {
    ceres_problem.AddParameterBlock(q[k].data(), 4, new ceres::EigenQuaternionManifold());
    ceres_problem.AddParameterBlock(t[k].data(), 3);
    ceres_problem.AddParameterBlock(&log_s[k], 1);
  }
  for (const PoseGraphEdge& e : problem.edges) {
    auto* cost = new ceres::AutoDiffCostFunction<Sim3EdgeCost, 7, 4, 3, 1, 4, 3, 1>(
        new Sim3EdgeCost(e.i_from_j, e.sqrt_information));
    ceres_problem.AddResidualBlock(cost, nullptr, q[e.i].data(), t[e.i].data(), &log_s[e.i],
                                   q[e.j].data(), t[e.j].data(), &log_s[e.j]);
  }
  for (size_t k = 0; k < n; ++k) {
    if (problem.fixed[k]) {
      ceres_problem.SetParameterBlockConstant(q[k].data());
      ceres_problem.SetParameterBlockConstant(t[k].data());
    }
    if (problem.fixed[k] || problem.fix_scale) ceres_problem.SetParameterBlockConstant(&log_s[k]);
  }
  PoseGraphResult result;
  if (!problem.edges.empty()) {
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    options.max_num_iterations = problem.iterations;
    options.num_threads = 1;
    options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &ceres_problem, &summary);
    result.initial_cost = summary.initial_cost;
    result.final_cost = summary.final_cost;
  }
  result.cam_from_world.resize(n);
  for (size_t k = 0; k < n; ++k) {
    Sim3d& g = result.cam_from_world[k];
    g.rotation = Eigen::Quaterniond(q[k].data()).normalized();
    g.translation = t[k];
    g.scale = std::exp(log_s[k]);
  }
  return result;
}

}  // namespace ademono
