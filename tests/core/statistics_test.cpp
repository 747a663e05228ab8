#include "ademono/core/statistics.h"

#include <gtest/gtest.h>

#include <vector>

namespace ademono {
namespace {

TEST(StatisticsTest, MedianOfOddEvenAndEmpty) {
  EXPECT_DOUBLE_EQ(Median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_DOUBLE_EQ(Median({4.0, 1.0, 3.0, 2.0}), 2.5);  // the mean of the two middle values
  EXPECT_DOUBLE_EQ(Median({5.0}), 5.0);
  EXPECT_DOUBLE_EQ(Median({}), 0.0);
}

TEST(StatisticsTest, RobustSpreadIsTheScaledMedianAbsoluteDeviation) {
  // Deviations from 2: 1, 0, 1, 8 -> median 1 -> 1.4826; the outlier 10 does not move it.
  EXPECT_DOUBLE_EQ(RobustSpread({1.0, 2.0, 3.0, 10.0}, 2.0), 1.4826);
  EXPECT_DOUBLE_EQ(RobustSpread({-2.0, 2.0, 1.0}), 1.4826 * 2.0);  // about 0 by default
  EXPECT_DOUBLE_EQ(RobustSpread({}), 0.0);
}

}  // namespace
}  // namespace ademono
