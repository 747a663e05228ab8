#pragma once
// Ceres residuals shared by the pose optimiser and bundle adjustment. A camera is a 6-vector
// (angle-axis rotation, translation) of cam_from_world, which keeps auto-differentiation cheap
// and needs no manifold.

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <cmath>
#include <limits>

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
