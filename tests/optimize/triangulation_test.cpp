#include "ademono/optimize/triangulation.h"

#include <gtest/gtest.h>

#include <cmath>

namespace ademono {
namespace {

Rigid3d Pose(const Eigen::Vector3d& axis_angle, const Eigen::Vector3d& translation) {
  Rigid3d pose = Rigid3d::Identity();
  if (axis_angle.norm() > 0) {
    pose.linear() =
        Eigen::AngleAxisd(axis_angle.norm(), axis_angle.normalized()).toRotationMatrix();
  }
  pose.translation() = translation;
  return pose;
}

Eigen::Vector2d Normalized(const Rigid3d& cam_from_world, const Eigen::Vector3d& x) {
  const Eigen::Vector3d p = cam_from_world * x;
  return p.head<2>() / p.z();
}

TEST(TriangulationTest, HandMadeStereoPair) {
  // Camera 2 sits 0.1 m to the right of camera 1 (cam2_from_world translation -0.1 in x). A point
  // at (0.2, -0.1, 2): camera 1 sees (0.1, -0.05), camera 2 (0.05, -0.05).
  const Rigid3d cam1 = Rigid3d::Identity();
  const Rigid3d cam2 = Pose(Eigen::Vector3d::Zero(), Eigen::Vector3d(-0.1, 0, 0));
  const auto x = TriangulatePoint(cam1, cam2, {0.1, -0.05}, {0.05, -0.05});
  ASSERT_TRUE(x.has_value());
  EXPECT_NEAR(x->x(), 0.2, 1e-12);
  EXPECT_NEAR(x->y(), -0.1, 1e-12);
  EXPECT_NEAR(x->z(), 2.0, 1e-12);
  // Rays from (0,0,0) and (0.1,0,0) to the point: cos = (0.2*0.1 + 0.01 + 4) / (|a| |b|).
  const Eigen::Vector3d a(0.2, -0.1, 2.0), b(0.1, -0.1, 2.0);
  EXPECT_NEAR(ParallaxCosine(cam1, cam2, *x), a.dot(b) / (a.norm() * b.norm()), 1e-15);
}

TEST(TriangulationTest, GeneralPosesReproduceThePoint) {
  const Rigid3d cam1 = Pose(Eigen::Vector3d(0.1, -0.2, 0.05), Eigen::Vector3d(0.3, -0.1, 0.2));
  const Rigid3d cam2 = Pose(Eigen::Vector3d(-0.05, 0.1, 0.2), Eigen::Vector3d(-0.2, 0.05, 0.4));
  const Eigen::Vector3d point(0.4, 0.3, 3.0);
  const auto x = TriangulatePoint(cam1, cam2, Normalized(cam1, point), Normalized(cam2, point));
  ASSERT_TRUE(x.has_value());
  EXPECT_LT((*x - point).norm(), 1e-9);
}

TEST(TriangulationTest, NoBaselineIsDegenerate) {
  // Same centre, different rotation: every ray pair meets only at the centre.
  const Rigid3d cam1 = Rigid3d::Identity();
  const Rigid3d cam2 = Pose(Eigen::Vector3d(0, 0.1, 0), Eigen::Vector3d::Zero());
  const Eigen::Vector3d point(0.1, 0.2, 2.0);
  const auto x = TriangulatePoint(cam1, cam2, Normalized(cam1, point), Normalized(cam2, point));
  EXPECT_FALSE(x.has_value());
  EXPECT_DOUBLE_EQ(ParallaxCosine(cam1, cam1, point), 1.0);
}

}  // namespace
}  // namespace ademono
