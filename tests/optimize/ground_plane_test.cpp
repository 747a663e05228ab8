#include "ademono/optimize/ground_plane.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/imgproc.hpp>
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
  // The inliers named are the road's points, the first `road` given, in order.
  ASSERT_EQ(plane.inliers.size(), road);
  for (size_t i = 0; i < road; ++i) EXPECT_EQ(plane.inliers[i], static_cast<int>(i));
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

// A depth map of a flat road `height` below a camera rotated by `cam_from_level` (the rest, above
// the horizon, invalid), at KITTI's size and intrinsics.
cv::Mat RoadDepth(const Camera& camera, double height, const Eigen::Matrix3d& cam_from_level) {
  cv::Mat depth(camera.height, camera.width, CV_32F, cv::Scalar(0));
  const Eigen::Vector3d n = cam_from_level * Eigen::Vector3d(0, -1, 0);  // towards the camera
  for (int r = 0; r < depth.rows; ++r) {
    for (int c = 0; c < depth.cols; ++c) {
      const Eigen::Vector3d ray((c - camera.cx) / camera.fx, (r - camera.cy) / camera.fy, 1.0);
      const double along = -n.dot(ray);  // the ray meets the plane -n.X = height
      if (along > 1e-6) depth.at<float>(r, c) = static_cast<float>(height / along);
    }
  }
  return depth;
}

Camera Kitti() { return Camera::Pinhole(1241, 376, 718.856, 607.1928, 185.2157); }

TEST(GroundPlaneTest, DenseRoadDepthGivesTheHeightAndNormal) {
  const Camera camera = Kitti();
  const Eigen::Matrix3d r = PitchRoll(1.5, -1);
  const cv::Mat depth = RoadDepth(camera, 1.65, r);
  const GroundPlane plane = EstimateGroundFromDepth(depth, camera);
  ASSERT_TRUE(plane.valid);
  EXPECT_NEAR(plane.height, 1.65, 1e-4);  // float depths
  EXPECT_NEAR(plane.normal.dot(r * Eigen::Vector3d(0, -1, 0)), 1.0, 1e-8);
  EXPECT_EQ(plane.inlier_share, 1.0);
  EXPECT_LT(plane.height_sigma, 1e-3);
  EXPECT_GT(plane.confidence, 0.9);
  // Every candidate lies in the corridor; a box over the lane's pixels removes them.
  const GroundFromDepthOptions options;
  const auto all = RoadCandidates(depth, camera, {}, options);
  for (const Eigen::Vector3d& p : all) {
    EXPECT_LE(std::abs(p.x()), options.max_lateral);
    EXPECT_GE(p.z(), options.min_depth);
    EXPECT_LE(p.z(), options.max_depth);
  }
  const auto rest = RoadCandidates(depth, camera, {cv::Rect2d(0, 300, 1241, 76)}, options);
  EXPECT_LT(rest.size(), all.size());
  EXPECT_GT(rest.size(), all.size() / 4);
  // Along a known normal: the same height, every point an inlier.
  const GroundPlane along = GroundHeightAlong(all, r * Eigen::Vector3d(0, -1, 0));
  ASSERT_TRUE(along.valid);
  EXPECT_NEAR(along.height, 1.65, 1e-4);
  EXPECT_EQ(along.num_inliers, static_cast<int>(all.size()));
  // Along the level axis instead, the 1.5 degree pitch shows as a spread of heights.
  const GroundPlane level = GroundHeightAlong(all, Eigen::Vector3d(0, -1, 0));
  EXPECT_GT(level.residual_sigma, 0.02);
  EXPECT_THROW(RoadCandidates(cv::Mat(10, 10, CV_32F), camera, {}, options), std::invalid_argument);
  GroundFromDepthOptions bad;
  bad.stride = 0;
  EXPECT_THROW(RoadCandidates(depth, camera, {}, bad), std::invalid_argument);
}

// A textured road seen from two poses: the image of view `cam_from_level` with the road a
// `height` below a level reference frame (x right, y down, z forward), the texture a smooth
// function of the road's (x, z) and the sky grey.
cv::Mat RenderRoad(const Camera& camera, double height, const Rigid3d& cam_from_level) {
  cv::Mat image(camera.height, camera.width, CV_8UC1, cv::Scalar(128));
  const Rigid3d level_from_cam = cam_from_level.inverse();
  const Eigen::Vector3d centre = level_from_cam.translation();
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) {
      const Eigen::Vector3d ray =
          level_from_cam.linear() *
          Eigen::Vector3d((c - camera.cx) / camera.fx, (r - camera.cy) / camera.fy, 1.0);
      if (!(ray.y() > 1e-6)) continue;
      const double s = (height - centre.y()) / ray.y();
      const double x = centre.x() + s * ray.x(), z = centre.z() + s * ray.z();
      const double v = 128 + 40 * std::sin(2.1 * x) * std::cos(1.3 * z) +
                       30 * std::sin(0.7 * x + 2.9 * z) + 20 * std::cos(3.7 * z - 1.1 * x);
      image.at<uint8_t>(r, c) = cv::saturate_cast<uint8_t>(v);
    }
  }
  cv::GaussianBlur(image, image, cv::Size(3, 3), 0.8);
  return image;
}

TEST(GroundPlaneTest, TwoViewsOfTheRoadGiveItsHeightInThePosesUnits) {
  const Camera camera = Kitti();
  // The rig pitched 1 degree down and rolled half a degree over a road 1.65 m below, moving
  // 1.4 m forward (two KITTI frames) while turning 1 degree.
  Rigid3d a_from_level = Rigid3d::Identity();
  a_from_level.linear() = PitchRoll(1.0, 0.5);
  Rigid3d b_from_a = Rigid3d::Identity();
  b_from_a.linear() =
      Eigen::AngleAxisd(1.0 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  b_from_a.translation() = Eigen::Vector3d(0.02, 0.0, -1.4);
  const cv::Mat a = RenderRoad(camera, 1.65, a_from_level);
  const cv::Mat b = RenderRoad(camera, 1.65, b_from_a * a_from_level);
  // Start level and 15 % high, as a network's reading would.
  GroundPlane initial;
  initial.height = 1.9;
  const GroundPlane plane = EstimateGroundFromTwoViews(a, b, b_from_a, camera, initial);
  ASSERT_TRUE(plane.valid);
  EXPECT_NEAR(plane.height, 1.65, 0.005);
  EXPECT_NEAR(plane.normal.dot(a_from_level.linear() * Eigen::Vector3d(0, -1, 0)), 1.0, 1e-4);
  EXPECT_GT(plane.inlier_share, 0.95);
  // In the map's units: the same poses at half scale give half the height.
  Rigid3d half = b_from_a;
  half.translation() *= 0.5;
  initial.height = 0.95;
  const GroundPlane scaled = EstimateGroundFromTwoViews(a, b, half, camera, initial);
  ASSERT_TRUE(scaled.valid);
  EXPECT_NEAR(scaled.height, 0.825, 0.0025);
  // With the normal held at the true one, only the height is fitted.
  TwoViewGroundOptions fixed;
  fixed.fit_normal = false;
  initial.height = 1.9;
  initial.normal = a_from_level.linear() * Eigen::Vector3d(0, -1, 0);
  const GroundPlane held = EstimateGroundFromTwoViews(a, b, b_from_a, camera, initial, {}, fixed);
  ASSERT_TRUE(held.valid);
  EXPECT_NEAR(held.height, 1.65, 0.005);
  EXPECT_NEAR(held.normal.dot(initial.normal), 1.0, 1e-12);
  // No motion, or a wall instead of a road (the sky's grey everywhere): no estimate.
  EXPECT_FALSE(EstimateGroundFromTwoViews(a, b, Rigid3d::Identity(), camera, initial).valid);
  const cv::Mat grey(camera.height, camera.width, CV_8UC1, cv::Scalar(128));
  EXPECT_FALSE(EstimateGroundFromTwoViews(grey, grey, b_from_a, camera, initial).valid);
  EXPECT_THROW(EstimateGroundFromTwoViews(a, cv::Mat(10, 10, CV_8UC1), b_from_a, camera, initial),
               std::invalid_argument);
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
