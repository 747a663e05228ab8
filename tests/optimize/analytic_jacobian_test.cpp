// The analytic reprojection Jacobians (optimize/residuals.h) against Ceres' auto-diff of the same
// residual, over rotations from zero through Ceres' small-angle branch to near pi, mono and
// u_right residuals, pixel-sigma and error-model depth weights, and the depth clamp.
#include <gtest/gtest.h>

#include <random>

#include "ademono/optimize/residuals.h"

namespace ademono {
namespace {

constexpr PinholeIntrinsics kIntrinsics{585, 580, 320, 240, 585 * 0.03};

// Largest |analytic - autodiff| relative to max(1, |autodiff|) over residuals and Jacobians.
template <int kDim>
double MaxDifference(const ImageObservation& obs, const double* camera, const double* point) {
  const internal::AnalyticBaCost<kDim> analytic(kIntrinsics, obs);
  const ceres::AutoDiffCostFunction<internal::BaResidual<kDim>, kDim, 6, 3> autodiff(
      new internal::BaResidual<kDim>(kIntrinsics, obs));
  const double* params[2] = {camera, point};
  double r_a[kDim], r_b[kDim], jc_a[kDim * 6], jc_b[kDim * 6], jp_a[kDim * 3], jp_b[kDim * 3];
  double* jac_a[2] = {jc_a, jp_a};
  double* jac_b[2] = {jc_b, jp_b};
  EXPECT_TRUE(analytic.Evaluate(params, r_a, jac_a));
  EXPECT_TRUE(autodiff.Evaluate(params, r_b, jac_b));
  double worst = 0;
  auto compare = [&](const double* a, const double* b, int n) {
    for (int i = 0; i < n; ++i)
      worst = std::max(worst, std::abs(a[i] - b[i]) / std::max(1.0, std::abs(b[i])));
  };
  compare(r_a, r_b, kDim);
  compare(jc_a, jc_b, kDim * 6);
  compare(jp_a, jp_b, kDim * 3);
  // Residual-only evaluation agrees with the full one.
  double r_only[kDim];
  EXPECT_TRUE(analytic.Evaluate(params, r_only, nullptr));
  for (int i = 0; i < kDim; ++i) EXPECT_EQ(r_only[i], r_a[i]);
  return worst;
}

ImageObservation RandomObservation(std::mt19937& rng, bool error_model) {
  std::uniform_real_distribution<double> pixel(0, 640), level(0, 7);
  ImageObservation obs;
  obs.pixel = Eigen::Vector2d(pixel(rng), pixel(rng) * 0.75);
  obs.u_right = obs.pixel.x() - 10.0;
  obs.inv_sigma2 = 1.0 / std::pow(1.2, 2 * static_cast<int>(level(rng)));
  if (error_model) obs.depth_inv_sigma = 0.37;
  return obs;
}

TEST(AnalyticJacobianTest, MatchesAutoDiffOverRotationsAndWeights) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1, 1), depth(0.4, 6.0);
  // Rotation angles: exactly zero, below Ceres' small-angle threshold (theta^2 < eps), in the
  // series range, moderate, and close to pi.
  const double angles[] = {0.0, 1e-9, 1e-5, 3e-3, 0.2, 1.3, 3.1};
  int cases = 0;
  for (double angle : angles) {
    for (int trial = 0; trial < 20; ++trial) {
      Eigen::Vector3d axis(unit(rng), unit(rng), unit(rng));
      axis.normalize();
      double camera[6];
      for (int i = 0; i < 3; ++i) camera[i] = angle * axis[i];
      for (int i = 3; i < 6; ++i) camera[i] = 0.5 * unit(rng);
      // A point in front of the camera: back-project a pixel at some depth into the world.
      Rigid3d cam_from_world = internal::ParamsToRigid(camera);
      const Eigen::Vector3d p_cam(unit(rng) * 2, unit(rng) * 1.5, depth(rng));
      const Eigen::Vector3d p_world = cam_from_world.inverse() * p_cam;
      const ImageObservation obs = RandomObservation(rng, trial % 2 == 1);
      EXPECT_LT(MaxDifference<2>(obs, camera, p_world.data()), 1e-9) << angle << " " << trial;
      EXPECT_LT(MaxDifference<3>(obs, camera, p_world.data()), 1e-9) << angle << " " << trial;
      cases += 2;
    }
  }
  EXPECT_EQ(cases, 7 * 20 * 2);
}

TEST(AnalyticJacobianTest, MatchesAutoDiffWhenDepthIsClamped) {
  std::mt19937 rng(5);
  const double camera[6] = {0.1, -0.2, 0.05, 0.0, 0.0, 0.0};
  const Rigid3d cam_from_world = internal::ParamsToRigid(camera);
  for (double z : {-1.0, 0.0, 5e-4}) {
    const Eigen::Vector3d p_world = cam_from_world.inverse() * Eigen::Vector3d(0.3, -0.2, z);
    const ImageObservation obs = RandomObservation(rng, z > 0);
    EXPECT_LT(MaxDifference<2>(obs, camera, p_world.data()), 1e-9) << z;
    EXPECT_LT(MaxDifference<3>(obs, camera, p_world.data()), 1e-9) << z;
  }
}

TEST(AnalyticJacobianTest, PoseCostMatchesAutoDiff) {
  std::mt19937 rng(9);
  const double camera[6] = {0.4, -0.3, 1.1, 0.2, -0.1, 0.3};
  const Rigid3d cam_from_world = internal::ParamsToRigid(camera);
  const Eigen::Vector3d point = cam_from_world.inverse() * Eigen::Vector3d(0.2, 0.1, 2.5);
  const ImageObservation obs = RandomObservation(rng, true);
  const internal::AnalyticPoseCost<3> analytic(kIntrinsics, obs, point);
  const ceres::AutoDiffCostFunction<internal::PoseOnlyResidual<3>, 3, 6> autodiff(
      new internal::PoseOnlyResidual<3>(kIntrinsics, obs, point));
  const double* params[1] = {camera};
  double r_a[3], r_b[3], j_a[18], j_b[18];
  double* jac_a[1] = {j_a};
  double* jac_b[1] = {j_b};
  ASSERT_TRUE(analytic.Evaluate(params, r_a, jac_a));
  ASSERT_TRUE(autodiff.Evaluate(params, r_b, jac_b));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(r_a[i], r_b[i], 1e-9);
  for (int i = 0; i < 18; ++i) EXPECT_NEAR(j_a[i], j_b[i], 1e-9 * std::max(1.0, std::abs(j_b[i])));
  // A non-trivial Jacobian: the rotation columns are not zero.
  EXPECT_GT(std::abs(j_a[0]) + std::abs(j_a[1]) + std::abs(j_a[2]), 1.0);
}

}  // namespace
}  // namespace ademono
