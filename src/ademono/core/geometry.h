#pragma once
// Rigid transforms. Naming follows COLMAP: `b_from_a` maps points in frame a to frame b, so
// `cam_from_world * p_world = p_cam` and `world_from_cam = cam_from_world.inverse()`.
// Eigen::Isometry3d is the one rigid-transform type used across ademono.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ademono {

using Rigid3d = Eigen::Isometry3d;

// From translation and unit quaternion (x, y, z, w order as in TUM files).
Rigid3d MakeRigid3d(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation);
// From a row-major 3x4 [R|t] (KITTI) or 4x4 matrix; re-orthonormalises R with an SVD.
Rigid3d MakeRigid3d(const Eigen::Matrix<double, 3, 4>& matrix);
Rigid3d MakeRigid3d(const Eigen::Matrix4d& matrix);
// Closest rotation to a 3x3 matrix (SVD projection).
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m);

// Rotation angle of a rotation matrix in radians, in [0, pi].
double RotationAngle(const Eigen::Matrix3d& rotation);

// Exponential and logarithm maps of SO(3) (axis-angle vector <-> rotation matrix).
Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& omega);
Eigen::Vector3d LogSO3(const Eigen::Matrix3d& rotation);

// The cross-product matrix: Skew(a) * b = a x b.
inline Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

}  // namespace ademono
