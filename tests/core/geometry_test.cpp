#include "ademono/core/geometry.h"

#include <cmath>

#include <gtest/gtest.h>

namespace ademono {
namespace {

TEST(Geometry, ExpLogRoundTrip) {
  const Eigen::Vector3d omega(0.1, -0.4, 0.25);
  EXPECT_NEAR((LogSO3(ExpSO3(omega)) - omega).norm(), 0.0, 1e-12);
  EXPECT_NEAR(RotationAngle(ExpSO3(omega)), omega.norm(), 1e-12);
}

TEST(Geometry, SkewIsTheCrossProductAndItsExpIsTheRotation) {
  const Eigen::Vector3d a(0.3, -1.2, 2.5), b(-0.7, 0.4, 1.1);
  EXPECT_NEAR((Skew(a) * b - a.cross(b)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((Skew(a).transpose() + Skew(a)).norm(), 0.0, 0.0);  // antisymmetric
  // First order: exp(w) ~ I + [w]x for a small w.
  const Eigen::Vector3d w = 1e-6 * a;
  EXPECT_NEAR((ExpSO3(w) - (Eigen::Matrix3d::Identity() + Skew(w))).norm(), 0.0, 1e-11);
}

TEST(Geometry, MakeRigidFromMatrixOrthonormalises) {
  Eigen::Matrix<double, 3, 4> m;
  m << 1.0001, 0, 0, 1, 0, 1, 0, 2, 0, 0, 0.9999, 3;
  const Rigid3d t = MakeRigid3d(m);
  EXPECT_NEAR((t.linear() * t.linear().transpose() - Eigen::Matrix3d::Identity()).norm(), 0, 1e-12);
  EXPECT_DOUBLE_EQ(t.translation().z(), 3.0);
}

TEST(Geometry, NamingConvention) {
  const Rigid3d world_from_cam =
      MakeRigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())),
                  Eigen::Vector3d(1, 0, 0));
  const Rigid3d cam_from_world = world_from_cam.inverse();
  const Eigen::Vector3d p_world(1, 1, 0);
  EXPECT_NEAR((cam_from_world * p_world - Eigen::Vector3d(1, 0, 0)).norm(), 0, 1e-12);
}

}  // namespace
}  // namespace ademono
