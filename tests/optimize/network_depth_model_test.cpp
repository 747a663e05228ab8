#include "ademono/optimize/network_depth_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace ademono {
namespace {

// A network whose view is 1 / z_net = (1 / z_true - b) / a, seen by a map at `map_scale`.
void MakePairs(double a, double b, double map_scale, double noise_log, int n, unsigned seed,
               std::vector<double>* map_depths, std::vector<double>* network_depths) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> depth(0.8, 6.0);
  std::normal_distribution<double> noise(0.0, noise_log);
  for (int i = 0; i < n; ++i) {
    const double z = depth(rng);
    const double inv_net = (1.0 / z - b) / a;
    network_depths->push_back(1.0 / inv_net * std::exp(noise(rng)));
    map_depths->push_back(z * map_scale);
  }
}

TEST(InverseDepthAffineTest, RecoversAnExactAffineMapInInverseDepth) {
  std::vector<double> zm, zn;
  MakePairs(0.87, 0.04, 1.0, 0.0, 200, 1, &zm, &zn);
  const InverseDepthAffine fit = FitInverseDepthAffine(zm, zn);
  ASSERT_TRUE(fit.valid);
  EXPECT_FALSE(fit.scale_only);
  EXPECT_NEAR(fit.a, 0.87, 1e-9);
  EXPECT_NEAR(fit.b, 0.04, 1e-9);
  EXPECT_NEAR(fit.sigma_log, 0.0, 1e-9);
  EXPECT_NEAR(fit.Map(zn[0]), zm[0], 1e-9);
}

TEST(InverseDepthAffineTest, TheMapsScaleGoesIntoBothTermsAndTheirRatioStays) {
  std::vector<double> zm, zn;
  MakePairs(1.1, -0.05, 0.37, 0.0, 200, 2, &zm, &zn);
  const InverseDepthAffine fit = FitInverseDepthAffine(zm, zn);
  ASSERT_TRUE(fit.valid);
  // 1 / (s z) = (a / s) / z_net + b / s.
  EXPECT_NEAR(fit.a, 1.1 / 0.37, 1e-9);
  EXPECT_NEAR(fit.b, -0.05 / 0.37, 1e-9);
  EXPECT_NEAR(fit.b / fit.a, -0.05 / 1.1, 1e-9);
}

TEST(InverseDepthAffineTest, RobustToWrongPointsAndMeasuresTheSpread) {
  std::vector<double> zm, zn;
  MakePairs(0.9, 0.03, 1.0, 0.05, 400, 3, &zm, &zn);
  // 15 % of the points badly wrong (wrong matches, movers).
  for (size_t i = 0; i < zm.size(); i += 7) zm[i] *= 2.5;
  const InverseDepthAffine fit = FitInverseDepthAffine(zm, zn);
  ASSERT_TRUE(fit.valid);
  EXPECT_NEAR(fit.a, 0.9, 0.03);
  EXPECT_NEAR(fit.b, 0.03, 0.02);
  EXPECT_NEAR(fit.sigma_log, 0.05, 0.015);
  EXPECT_LT(fit.num_inliers, fit.num_points);
}

TEST(InverseDepthAffineTest, ANarrowDepthRangeFitsTheScaleOnly) {
  std::vector<double> zm, zn;
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> depth(3.0, 3.3);
  for (int i = 0; i < 100; ++i) {
    const double z = depth(rng);
    zm.push_back(z);
    zn.push_back(z * 1.2);
  }
  const InverseDepthAffine fit = FitInverseDepthAffine(zm, zn);
  ASSERT_TRUE(fit.valid);
  EXPECT_TRUE(fit.scale_only);
  EXPECT_EQ(fit.b, 0.0);
  EXPECT_NEAR(fit.a, 1.2, 1e-9);
  EXPECT_NEAR(fit.median_ratio, 1.2, 1e-9);
}

TEST(InverseDepthAffineTest, IndependentNoiseSharesNothing) {
  // Per-point noise after an affine map: the depth bins' medians stay within their own scatter.
  for (unsigned seed : {4u, 5u, 6u}) {
    std::vector<double> zm, zn;
    MakePairs(0.9, 0.03, 1.0, 0.1, 600, seed, &zm, &zn);
    const InverseDepthAffine fit = FitInverseDepthAffine(zm, zn);
    ASSERT_TRUE(fit.valid);
    // (The map compresses the network's noise: d log z_map / d log z_net < 1 with b > 0.)
    EXPECT_GT(fit.sigma_log, 0.06);
    // What is left is the bins' medians' own scatter (about 0.007 each for 200 points).
    EXPECT_LT(fit.shared_sigma_log, 0.25 * fit.sigma_log) << "seed " << seed;
  }
  std::vector<double> zm, zn;
  MakePairs(0.87, 0.04, 1.0, 0.0, 200, 1, &zm, &zn);
  EXPECT_NEAR(FitInverseDepthAffine(zm, zn).shared_sigma_log, 0.0, 1e-9);
}

TEST(InverseDepthAffineTest, ADepthDependentErrorTheAffineMapCannotFollowIsShared) {
  // A network that reads near points long and the middle short, far points long again (a
  // bend in log depth no affine map in inverse depth follows), plus per-point noise.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> log_depth(std::log(2.0), std::log(40.0));
  std::normal_distribution<double> noise(0.0, 0.1);
  std::vector<double> zm, zn;
  const double mid = 0.5 * (std::log(2.0) + std::log(40.0)), half = 0.5 * std::log(20.0);
  for (int i = 0; i < 900; ++i) {
    const double l = log_depth(rng);
    const double u = (l - mid) / half;  // -1 .. 1
    const double bend = 0.25 * (2.0 * u * u - 1.0);  // +0.25 at the ends, -0.25 in the middle
    zm.push_back(std::exp(l));
    zn.push_back(std::exp(l + bend + noise(rng)));
  }
  const InverseDepthAffine fit = FitInverseDepthAffine(zm, zn);
  ASSERT_TRUE(fit.valid);
  // Bins of a third each: the middle one reads about 0.2 short, the outer ones about 0.1 long
  // of the fit (what the affine map absorbs of the bend aside).
  EXPECT_GT(fit.shared_sigma_log, 0.08);
  EXPECT_LT(fit.shared_sigma_log, 0.25);
  EXPECT_GT(fit.sigma_log, fit.shared_sigma_log);
}

TEST(InverseDepthAffineTest, TooFewPointsIsNoFit) {
  const InverseDepthAffine fit = FitInverseDepthAffine({1, 2, 3}, {1, 2, 3});
  EXPECT_FALSE(fit.valid);
  EXPECT_EQ(fit.num_points, 3);
}

}  // namespace
}  // namespace ademono
