#include "ademono/optimize/depth_scale.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace ademono {
namespace {

TEST(DepthScaleTest, ExactRatioIsRecovered) {
  const std::vector<double> source{1.0, 2.0, 3.0, 4.0, 5.0};
  std::vector<double> reference;
  for (double s : source) reference.push_back(1.25 * s);
  DepthScaleOptions options;
  options.min_points = 5;
  const DepthScaleEstimate e = EstimateDepthScale(reference, source, options);
  ASSERT_TRUE(e.valid);
  EXPECT_NEAR(e.scale, 1.25, 1e-12);
  EXPECT_EQ(e.num_points, 5);
  // Identical log ratios: the spread is the floor, and the standard error shrinks with sqrt(n).
  EXPECT_DOUBLE_EQ(e.log_sigma, options.min_sigma);
  EXPECT_NEAR(e.log_stderr, options.min_sigma / std::sqrt(5.0), 1e-15);
}

TEST(DepthScaleTest, OutliersDoNotMoveTheEstimate) {
  // 18 points at ratio 2 with a symmetric +-1% spread, plus 2 gross outliers (wrong matches).
  std::vector<double> reference, source;
  for (int i = 0; i < 9; ++i) {
    source.push_back(1.0 + i);
    reference.push_back(2.0 * 1.01 * (1.0 + i));
    source.push_back(1.5 + i);
    reference.push_back(2.0 / 1.01 * (1.5 + i));
  }
  source.push_back(2.0);
  reference.push_back(40.0);
  source.push_back(3.0);
  reference.push_back(0.3);
  DepthScaleOptions options;
  options.min_points = 10;
  const DepthScaleEstimate e = EstimateDepthScale(reference, source, options);
  ASSERT_TRUE(e.valid);
  EXPECT_NEAR(e.scale, 2.0, 1e-9);  // symmetric in log: the outliers get bounded weights
  EXPECT_NEAR(e.log_sigma, 1.4826 * std::log(1.01), 1e-9);
  EXPECT_EQ(e.num_points, 20);
}

TEST(DepthScaleTest, HandComputedHuberStep) {
  // Log ratios 0, 0, 0.1: median 0, MAD 0 -> sigma = min_sigma = 0.05, threshold 0.05.
  // IRLS from 0: weights 1, 1, 0.05 / 0.1 = 0.5 -> mu = 0.05 / 2.5 = 0.02; next: residual of the
  // third is 0.08 -> w = 0.625, mu = 0.0625 / 2.625; it converges to the Huber solution
  // mu = 0.025, where the clipped residual 0.05 balances the two residuals -mu.
  const std::vector<double> source{1.0, 1.0, 1.0};
  const std::vector<double> reference{1.0, 1.0, std::exp(0.1)};
  DepthScaleOptions options;
  options.min_points = 3;
  options.huber_k = 1.0;
  options.min_sigma = 0.05;
  options.iterations = 100;
  const DepthScaleEstimate e = EstimateDepthScale(reference, source, options);
  ASSERT_TRUE(e.valid);
  EXPECT_NEAR(std::log(e.scale), 0.025, 1e-8);
  options.iterations = 1;
  EXPECT_NEAR(std::log(EstimateDepthScale(reference, source, options).scale), 0.02, 1e-12);
}

TEST(DepthScaleTest, InvalidPairsAreSkippedAndTooFewGiveNoEstimate) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> reference{2.0, 0.0, -1.0, nan, 4.0, 6.0};
  const std::vector<double> source{1.0, 1.0, 1.0, 1.0, 2.0, 3.0};
  DepthScaleOptions options;
  options.min_points = 3;
  DepthScaleEstimate e = EstimateDepthScale(reference, source, options);
  ASSERT_TRUE(e.valid);
  EXPECT_EQ(e.num_points, 3);
  EXPECT_NEAR(e.scale, 2.0, 1e-12);
  options.min_points = 4;
  e = EstimateDepthScale(reference, source, options);
  EXPECT_FALSE(e.valid);
  EXPECT_EQ(e.num_points, 3);
  EXPECT_DOUBLE_EQ(e.scale, 1.0);
}

TEST(DepthScaleTest, RejectsBadArguments) {
  EXPECT_THROW(EstimateDepthScale({1.0}, {1.0, 2.0}), std::invalid_argument);
  DepthScaleOptions options;
  options.min_points = 0;
  EXPECT_THROW(EstimateDepthScale({1.0}, {1.0}, options), std::invalid_argument);
}

}  // namespace
}  // namespace ademono
