#pragma once
// Ceres residuals shared by the pose optimiser and bundle adjustment. A camera is a 6-vector
// (angle-axis rotation, translation) of cam_from_world, which keeps auto-differentiation cheap
// and needs no manifold.

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <cmath>
#include <limits>

#include "ademono/core/geometry.h"
#include "ademono/optimize/optimizer_types.h"

namespace ademono::internal {

inline void RigidToParams(const Rigid3d& cam_from_world, double* params) {
  const Eigen::AngleAxisd angle_axis(cam_from_world.rotation());
  const Eigen::Vector3d omega = angle_axis.angle() * angle_axis.axis();
  for (int i = 0; i < 3; ++i) {
    params[i] = omega[i];
    params[3 + i] = cam_from_world.translation()[i];
  }
}

inline Rigid3d ParamsToRigid(const double* params) {
  const Eigen::Vector3d omega(params[0], params[1], params[2]);
  const double angle = omega.norm();
  Rigid3d result = Rigid3d::Identity();
  if (angle > 1e-15) result.linear() = Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
  result.translation() = Eigen::Vector3d(params[3], params[4], params[5]);
  return result;
}

// Projects a world point through a camera into (u, v[, u_right]) residuals scaled by 1/sigma.
template <int kDim>
struct ProjectionResidual {
  static constexpr int kDimension = kDim;
  ProjectionResidual(const PinholeIntrinsics& k, const ImageObservation& obs)
      : k(k),
        u(obs.pixel.x()),
        v(obs.pixel.y()),
        ur(obs.u_right),
        scale(std::sqrt(obs.inv_sigma2)),
        depth_scale(std::sqrt(obs.DepthWeight2())) {}

  template <typename T>
  bool Compute(const T* camera, const T* point_world, T* residual) const {
    T p[3];
    ceres::AngleAxisRotatePoint(camera, point_world, p);
    p[0] += camera[3];
    p[1] += camera[4];
    p[2] += camera[5];
    // Points crossing behind the camera are pinned near the principal plane instead of
    // dividing by zero; the chi2 test marks them as outliers afterwards.
    if (p[2] < T(1e-3)) p[2] = T(1e-3);
    const T inv_z = T(1.0) / p[2];
    const T pu = T(k.fx) * p[0] * inv_z + T(k.cx);
    const T pv = T(k.fy) * p[1] * inv_z + T(k.cy);
    residual[0] = T(scale) * (pu - T(u));
    residual[1] = T(scale) * (pv - T(v));
    if constexpr (kDim == 3) residual[2] = T(depth_scale) * (pu - T(k.bf) * inv_z - T(ur));
    return true;
  }

  PinholeIntrinsics k;
  double u, v, ur, scale, depth_scale;
};

// Pose-only: the point is a constant.
template <int kDim>
struct PoseOnlyResidual : ProjectionResidual<kDim> {
  PoseOnlyResidual(const PinholeIntrinsics& k, const ImageObservation& obs,
                   const Eigen::Vector3d& point)
      : ProjectionResidual<kDim>(k, obs), point(point) {}
  template <typename T>
  bool operator()(const T* camera, T* residual) const {
    const T p[3] = {T(point.x()), T(point.y()), T(point.z())};
    return this->Compute(camera, p, residual);
  }
  Eigen::Vector3d point;
};

// Bundle adjustment: camera and point are both parameters.
template <int kDim>
struct BaResidual : ProjectionResidual<kDim> {
  using ProjectionResidual<kDim>::ProjectionResidual;
  template <typename T>
  bool operator()(const T* camera, const T* point, T* residual) const {
    return this->Compute(camera, point, residual);
  }
};

// A camera's rotation and what its derivatives need, computed once per camera: R(omega) (Ceres'
// AngleAxisToRotationMatrix) and SO(3)'s left Jacobian J_l(omega), so that
//   d(R X)/d omega = -[q]x J_l(omega)  at q = R X;
// below Ceres' small-angle threshold AngleAxisRotatePoint uses X + omega x X, whose derivative
// is -[X]x.
struct CameraRotation {
  Eigen::Matrix3d rotation;
  Eigen::Matrix3d left_jacobian;  // unused when small
  bool small = false;

  CameraRotation() = default;
  explicit CameraRotation(const double* camera) {
    using Mat3 = Eigen::Matrix3d;
    const Eigen::Map<const Eigen::Vector3d> omega(camera);
    const double theta2 = omega.squaredNorm();
    small = !(theta2 > std::numeric_limits<double>::epsilon());  // Ceres' branch
    const Mat3 omega_x = Skew(omega);
    if (small) {
      rotation = Mat3::Identity() + omega_x;
      return;
    }
    const double theta = std::sqrt(theta2);
    // (1 - cos)/theta^2 and (theta - sin)/theta^3, by series where they cancel badly.
    double a, b;
    if (theta < 1e-2) {
      a = 0.5 - theta2 / 24.0 + theta2 * theta2 / 720.0;
      b = 1.0 / 6.0 - theta2 / 120.0 + theta2 * theta2 / 5040.0;
    } else {
      a = (1.0 - std::cos(theta)) / theta2;
      b = (theta - std::sin(theta)) / (theta2 * theta);
    }
    left_jacobian = Mat3::Identity() + a * omega_x + b * omega_x * omega_x;
    ceres::AngleAxisToRotationMatrix(camera, ceres::ColumnMajorAdapter3x3(rotation.data()));
  }
  // d(R X)/d omega for the point X rotated to q.
  Eigen::Matrix3d DerivativeAt(const double* point_world, const double* q) const {
    if (small) return -Skew(Eigen::Map<const Eigen::Vector3d>(point_world));
    return -Skew(Eigen::Vector3d(q[0], q[1], q[2])) * left_jacobian;
  }
};

// The projection residual (u, v[, u_right]) scaled by 1/sigma and, when asked, its Jacobians,
// from the rotated point q = R X and the camera's translation t (p = q + t); `rotation` gives
// R and d q/d omega. `jac_camera` is kDim x 6 and `jac_point` kDim x 3, row-major; either may be
// null. The depth clamp has zero derivative, as in auto-diff.
template <int kDim>
void ProjectRotated(const ProjectionResidual<kDim>& r, const double* q, const double* t,
                    const double* point_world, const CameraRotation* rotation, double* residual,
                    double* jac_camera, double* jac_point) {
  double p[3] = {q[0] + t[0], q[1] + t[1], q[2] + t[2]};
  const bool clamped = p[2] < 1e-3;
  if (clamped) p[2] = 1e-3;
  const double inv_z = 1.0 / p[2];
  const PinholeIntrinsics& k = r.k;
  const double pu = k.fx * p[0] * inv_z + k.cx;
  const double pv = k.fy * p[1] * inv_z + k.cy;
  residual[0] = r.scale * (pu - r.u);
  residual[1] = r.scale * (pv - r.v);
  if constexpr (kDim == 3) residual[2] = r.depth_scale * (pu - k.bf * inv_z - r.ur);
  if (jac_camera == nullptr && jac_point == nullptr) return;

  Eigen::Matrix<double, kDim, 3> dr_dp;
  const double inv_z2 = clamped ? 0.0 : inv_z * inv_z;
  dr_dp.row(0) << r.scale * k.fx * inv_z, 0.0, -r.scale * k.fx * p[0] * inv_z2;
  dr_dp.row(1) << 0.0, r.scale * k.fy * inv_z, -r.scale * k.fy * p[1] * inv_z2;
  if constexpr (kDim == 3)
    dr_dp.row(2) << r.depth_scale * k.fx * inv_z, 0.0,
        r.depth_scale * (k.bf - k.fx * p[0]) * inv_z2;
  if (jac_camera != nullptr) {
    Eigen::Map<Eigen::Matrix<double, kDim, 6, Eigen::RowMajor>> j(jac_camera);
    j.template leftCols<3>() = dr_dp * rotation->DerivativeAt(point_world, q);
    j.template rightCols<3>() = dr_dp;
  }
  if (jac_point != nullptr) {
    Eigen::Map<Eigen::Matrix<double, kDim, 3, Eigen::RowMajor>> j(jac_point);
    j = dr_dp * rotation->rotation;
  }
}

// The same residual with closed-form Jacobians (about 3x cheaper than auto-diff's dual numbers).
// camera = (omega, t) of cam_from_world: p = R(omega) X + t, so dp/domega is d(R X)/d omega
// (CameraRotation), dp/dt = I and dp/dX = R.
// `rotation`, when given, is CameraRotation(camera), built once by a caller that evaluates many
// points with one camera (the same numbers as building it here).
template <int kDim>
void EvaluateProjection(const ProjectionResidual<kDim>& r, const double* camera,
                        const double* point_world, double* residual, double* jac_camera,
                        double* jac_point, const CameraRotation* rotation = nullptr) {
  double q[3];
  ceres::AngleAxisRotatePoint(camera, point_world, q);
  if (jac_camera == nullptr && jac_point == nullptr) {
    ProjectRotated(r, q, camera + 3, point_world, nullptr, residual, nullptr, nullptr);
    return;
  }
  if (rotation != nullptr) {
    ProjectRotated(r, q, camera + 3, point_world, rotation, residual, jac_camera, jac_point);
    return;
  }
  const CameraRotation own(camera);
  ProjectRotated(r, q, camera + 3, point_world, &own, residual, jac_camera, jac_point);
}

// Bundle adjustment cost with analytic Jacobians (parameter blocks: camera 6, point 3).
template <int kDim>
class AnalyticBaCost final : public ceres::SizedCostFunction<kDim, 6, 3> {
 public:
  AnalyticBaCost(const PinholeIntrinsics& k, const ImageObservation& obs) : r_(k, obs) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    EvaluateProjection(r_, parameters[0], parameters[1], residuals,
                       jacobians != nullptr ? jacobians[0] : nullptr,
                       jacobians != nullptr ? jacobians[1] : nullptr);
    return true;
  }

 private:
  ProjectionResidual<kDim> r_;
};

// Pose-only cost with analytic Jacobians (parameter block: camera 6; the point is a constant).
template <int kDim>
class AnalyticPoseCost final : public ceres::SizedCostFunction<kDim, 6> {
 public:
  AnalyticPoseCost(const PinholeIntrinsics& k, const ImageObservation& obs,
                   const Eigen::Vector3d& point)
      : r_(k, obs), point_(point) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    EvaluateProjection(r_, parameters[0], point_.data(), residuals,
                       jacobians != nullptr ? jacobians[0] : nullptr, nullptr);
    return true;
  }

 private:
  ProjectionResidual<kDim> r_;
  Eigen::Vector3d point_;
};

// Squared scaled error (chi2) and the camera-frame depth of a point, in plain doubles.
inline double ObservationChi2(const PinholeIntrinsics& k, const ImageObservation& obs,
                              const Rigid3d& cam_from_world, const Eigen::Vector3d& point_world,
                              double* depth) {
  const Eigen::Vector3d p = cam_from_world * point_world;
  if (depth != nullptr) *depth = p.z();
  if (p.z() <= 1e-6) return std::numeric_limits<double>::infinity();
  const double inv_z = 1.0 / p.z();
  const double pu = k.fx * p.x() * inv_z + k.cx;
  const double pv = k.fy * p.y() * inv_z + k.cy;
  double chi2 =
      (pu - obs.pixel.x()) * (pu - obs.pixel.x()) + (pv - obs.pixel.y()) * (pv - obs.pixel.y());
  if (obs.HasDepth()) {
    const double ur = pu - k.bf * inv_z;
    const double e2 = (ur - obs.u_right) * (ur - obs.u_right);
    if (obs.depth_inv_sigma > 0.0) {
      return chi2 * obs.inv_sigma2 + e2 * obs.depth_inv_sigma * obs.depth_inv_sigma;
    }
    chi2 += e2;
  }
  return chi2 * obs.inv_sigma2;
}

}  // namespace ademono::internal
