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
  explicit Sim3EdgeCost(const Sim3d& measured) {
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
    return true;
  }
  double inv_scale = 1;
  Eigen::Quaterniond inv_rotation;
  Eigen::Vector3d inv_translation;
};

}  // namespace

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
        new Sim3EdgeCost(e.i_from_j));
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
