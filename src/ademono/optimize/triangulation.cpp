#include "ademono/optimize/triangulation.h"

#include <Eigen/SVD>
#include <cmath>

namespace ademono {

std::optional<Eigen::Vector3d> TriangulatePoint(const Rigid3d& cam1_from_world,
                                                const Rigid3d& cam2_from_world,
                                                const Eigen::Vector2d& normalized1,
                                                const Eigen::Vector2d& normalized2) {
  const Eigen::Matrix<double, 3, 4> P1 = cam1_from_world.matrix().topRows<3>();
  const Eigen::Matrix<double, 3, 4> P2 = cam2_from_world.matrix().topRows<3>();
  Eigen::Matrix4d A;
  A.row(0) = normalized1.x() * P1.row(2) - P1.row(0);
  A.row(1) = normalized1.y() * P1.row(2) - P1.row(1);
  A.row(2) = normalized2.x() * P2.row(2) - P2.row(0);
  A.row(3) = normalized2.y() * P2.row(2) - P2.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d X = svd.matrixV().col(3);
  // A rank below 3 leaves the smallest two singular values equal: no unique solution.
  const Eigen::Vector4d sv = svd.singularValues();
  if (!(sv(2) > 1e-12 * sv(0)) || std::abs(X(3)) < 1e-12) return std::nullopt;
  const Eigen::Vector3d point = X.head<3>() / X(3);
  if (!point.allFinite()) return std::nullopt;
  return point;
}

double ParallaxCosine(const Rigid3d& cam1_from_world, const Rigid3d& cam2_from_world,
                      const Eigen::Vector3d& point_world) {
  const Eigen::Vector3d ray1 = point_world - cam1_from_world.inverse().translation();
  const Eigen::Vector3d ray2 = point_world - cam2_from_world.inverse().translation();
  const double norms = ray1.norm() * ray2.norm();
  if (!(norms > 0)) return 1.0;
  return ray1.dot(ray2) / norms;
}

}  // namespace ademono
