#include "ademono/optimize/ground_plane.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

namespace ademono {
namespace {

// A road `height` below a camera pitched and rolled by a few degrees: points on a grid ahead
// (x right, y down, z forward in the camera frame).
std::vector<Eigen::Vector3d> Road(double height, const Eigen::Matrix3d& cam_from_level,
                                  double x_from, double x_to) {
  std::vector<Eigen::Vector3d> points;
  for (double z = 5; z <= 25; z += 1.0) {
    for (double x = x_from; x <= x_to; x += 0.5)
      points.push_back(cam_from_level * Eigen::Vector3d(x, height, z));
  }
  return points;
}

Eigen::Matrix3d PitchRoll(double pitch_deg, double roll_deg) {
  return (Eigen::AngleAxisd(pitch_deg * M_PI / 180, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(roll_deg * M_PI / 180, Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

TEST(GroundPlaneTest, ExactRoadGivesTheCameraHeightAndNormal) {
  const Eigen::Matrix3d r = PitchRoll(3, -2);
  const GroundPlane plane = EstimateGroundPlane(Road(1.65, r, -4, 4));
  ASSERT_TRUE(plane.valid);
  EXPECT_NEAR(plane.height, 1.65, 1e-9);
  EXPECT_NEAR(plane.normal.dot(r * Eigen::Vector3d(0, -1, 0)), 1.0, 1e-12);
  EXPECT_EQ(plane.num_inliers, 21 * 17);
}

TEST(GroundPlaneTest, WallsAndCarsAreNotTheGround) {
  const Eigen::Matrix3d r = PitchRoll(1, 1);
  std::vector<Eigen::Vector3d> points = Road(1.65, r, -3, 3);
  const size_t road = points.size();
  // A facade to the right down to 15 cm above the road and the back of a car: together more
  // points than the road.
  for (double y = -3; y <= 1.55; y += 0.1) {
    for (double z = 6; z <= 24; z += 1.5) points.push_back(r * Eigen::Vector3d(8, y, z));
  }
  for (double x = -1; x <= 1; x += 0.1) {
    for (double y = 0.2; y <= 1.5; y += 0.1) points.push_back(r * Eigen::Vector3d(x, y, 9));
  }
  ASSERT_GT(points.size(), 2 * road);
  const GroundPlane plane = EstimateGroundPlane(points);
  ASSERT_TRUE(plane.valid);
  EXPECT_NEAR(plane.height, 1.65, 1e-9);
  EXPECT_EQ(plane.num_inliers, static_cast<int>(road));
}

TEST(GroundPlaneTest, AKerbAsPopulousAsTheRoadTiltsThePlane) {
  // The limitation that makes tracking fit only a corridor ahead (depth.ground_max_lateral): a
  // sidewalk 15 cm up (9 % of the height, inside no band a network's noise allows) beside the
  // road draws a plane through both.
  std::vector<Eigen::Vector3d> points = Road(1.65, PitchRoll(0, 0), -3, 3);
  const GroundPlane road = EstimateGroundPlane(points);
  for (const Eigen::Vector3d& p : Road(1.50, PitchRoll(0, 0), 6, 9)) points.push_back(p);
  const GroundPlane both = EstimateGroundPlane(points);
  ASSERT_TRUE(road.valid && both.valid);
  EXPECT_NEAR(road.height, 1.65, 1e-9);
  EXPECT_GT(std::abs(both.height - 1.65), 0.005);
  EXPECT_GT(both.num_inliers, road.num_inliers);
}

TEST(GroundPlaneTest, NetworkLikeDepthNoiseAveragesOut) {
  // Each point's depth off by 3 % (one sigma) along its ray, like a network's at 20 m: a
  // point's own height is as far off, the plane's within 1 % (its tilt is free too).
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.03);
  std::vector<Eigen::Vector3d> points = Road(1.65, PitchRoll(2, 0), -4, 4);
  for (Eigen::Vector3d& p : points) p *= 1.0 + noise(rng);
  GroundPlaneOptions options;
  options.inlier_ratio = 0.1;
  const GroundPlane plane = EstimateGroundPlane(points, options);
  ASSERT_TRUE(plane.valid);
  EXPECT_NEAR(plane.height, 1.65, 0.0165);  // over seeds 1-5: 1.638-1.656
  EXPECT_EQ(EstimateGroundPlane(points, options).height, plane.height);  // deterministic
}

TEST(GroundPlaneTest, NoEstimateWithoutAGround) {
  // Too few points, a ground tilted beyond max_tilt_deg, a plane above the camera (a ceiling).
  EXPECT_FALSE(EstimateGroundPlane(Road(1.65, PitchRoll(0, 0), 0, 0.5)).valid);
  EXPECT_FALSE(EstimateGroundPlane(Road(1.65, PitchRoll(25, 0), -4, 4)).valid);
  GroundPlaneOptions options;
  options.max_tilt_deg = 30;
  EXPECT_TRUE(EstimateGroundPlane(Road(1.65, PitchRoll(25, 0), -4, 4), options).valid);
  EXPECT_FALSE(EstimateGroundPlane(Road(-1.65, PitchRoll(0, 0), -4, 4)).valid);
  EXPECT_FALSE(EstimateGroundPlane({}).valid);
}

TEST(GroundPlaneTest, OptionsAreChecked) {
  GroundPlaneOptions options;
  EXPECT_NO_THROW(options.Check());
  options.max_tilt_deg = 95;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = {};
  options.min_inliers = 2;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = {};
  options.inlier_ratio = 0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace ademono
