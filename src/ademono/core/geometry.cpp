#include "ademono/core/geometry.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace ademono {

Rigid3d MakeRigid3d(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation) {
  Rigid3d t = Rigid3d::Identity();
  t.linear() = rotation.normalized().toRotationMatrix();
  t.translation() = translation;
  return t;
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
  if (r.determinant() < 0) {
    Eigen::Matrix3d u = svd.matrixU();
    u.col(2) *= -1;
    r = u * svd.matrixV().transpose();
  }
  return r;
}

Rigid3d MakeRigid3d(const Eigen::Matrix<double, 3, 4>& matrix) {
  Rigid3d t = Rigid3d::Identity();
  t.linear() = NearestRotation(matrix.leftCols<3>());
  t.translation() = matrix.col(3);
  return t;
}

Rigid3d MakeRigid3d(const Eigen::Matrix4d& matrix) {
  return MakeRigid3d(Eigen::Matrix<double, 3, 4>(matrix.topRows<3>()));
}

double RotationAngle(const Eigen::Matrix3d& rotation) {
  const double c = std::clamp((rotation.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c);
}

Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& omega) {
  const double angle = omega.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
}

Eigen::Vector3d LogSO3(const Eigen::Matrix3d& rotation) {
  Eigen::AngleAxisd aa(rotation);
  return aa.angle() * aa.axis();
}

}  // namespace ademono
