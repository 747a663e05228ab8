#include "ademono/feature/matching.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace ademono {
namespace {

// A descriptor row with the first `ones` bits set.
cv::Mat Desc(int ones) {
  cv::Mat d(1, 32, CV_8UC1, cv::Scalar(0));
  for (int b = 0; b < ones; ++b) d.at<uchar>(0, b / 8) |= static_cast<uchar>(1 << (b % 8));
  return d;
}

TEST(RotationHistogramTest, KeepsThreeLargestBinsAboveTenPercent) {
  RotationHistogram h;
  int id = 0;
  for (int i = 0; i < 10; ++i) h.Add(10.f, 10.f, id++);  // 0..9: no rotation
  for (int i = 0; i < 5; ++i) h.Add(100.f, 10.f, id++);  // 10..14: 90 degrees
  for (int i = 0; i < 2; ++i) h.Add(55.f, 10.f, id++);   // 15..16: 45 degrees
  h.Add(190.f, 10.f, id++);                              // 17: 180 degrees, fourth bin
  h.Add(9.f, 10.f, id++);                                // 18: -1 degree wraps into bin 0
  EXPECT_EQ(h.InconsistentMatches(), std::vector<int>({17}));
  EXPECT_EQ(h.ConsistentMatches().size(), 18u);
}

TEST(RotationHistogramTest, DropsWeakSecondaryPeaks) {
  RotationHistogram h;
  for (int i = 0; i < 30; ++i) h.Add(0.f, 0.f, i);
  h.Add(120.f, 0.f, 30);  // 1 vote < 10% of 30
  h.Add(240.f, 0.f, 31);
  h.Add(240.f, 0.f, 32);  // 2 votes < 3
  EXPECT_EQ(h.InconsistentMatches(), std::vector<int>({30, 31, 32}));
  EXPECT_TRUE(RotationHistogram().InconsistentMatches().empty());
}

TEST(RotationHistogramTest, BinsRoundToTheNearestAndWrapAt360) {
  RotationHistogram h;
  for (int i = 0; i < 10; ++i) h.Add(0.f, 0.f, i);  // bin 0
  h.Add(359.f, 0.f, 10);                            // 29.9 rounds to 30: wraps into bin 0
  h.Add(5.9f, 0.f, 11);                             // 0.49: bin 0
  h.Add(0.f, 6.1f, 12);                             // 353.9 -> 29.49: bin 29, alone
  h.Add(12.f, 0.f, 12);                             // the same id twice is reported twice
  h.Add(12.f, 0.f, 12);
  h.Add(12.f, 0.f, 13);
  // Bins: 0 holds 12, 1 holds 3 (>= 10%), 29 holds 1 (< 10%).
  EXPECT_EQ(h.InconsistentMatches(), std::vector<int>({12}));
  EXPECT_EQ(h.ConsistentMatches(),
            std::vector<int>({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 12, 13}));
}

TEST(MatchBruteForceTest, RatioTestMaxDistanceAndUniqueness) {
  cv::Mat train;
  cv::vconcat(std::vector<cv::Mat>{Desc(0), Desc(100), Desc(200)}, train);
  cv::Mat query;
  // q0: exact match of t0 (0 vs 100): kept. q1: 50 bits, equidistant from t0 and t1: ratio fails.
  // q2: 190 bits: t2 at 10, t1 at 90: kept. q3: 195 bits: t2 at 5: kept. q4: 256 bits is 56 from
  // its nearest t2, beyond max_distance 50.
  cv::vconcat(std::vector<cv::Mat>{Desc(0), Desc(50), Desc(190), Desc(195), Desc(256)}, query);
  BruteForceMatchOptions options;
  options.ratio = 0.8;
  options.max_distance = 50;
  options.unique_train = false;
  std::vector<cv::DMatch> m = MatchBruteForce(query, train, options);
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[0].queryIdx, 0);
  EXPECT_EQ(m[0].trainIdx, 0);
  EXPECT_EQ(m[0].distance, 0.f);
  EXPECT_EQ(m[1].queryIdx, 2);
  EXPECT_EQ(m[1].trainIdx, 2);
  EXPECT_EQ(m[1].distance, 10.f);
  EXPECT_EQ(m[2].queryIdx, 3);
  EXPECT_EQ(m[2].distance, 5.f);
  options.unique_train = true;  // q2 and q3 both want t2: the closer q3 keeps it
  m = MatchBruteForce(query, train, options);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[1].queryIdx, 3);
  EXPECT_TRUE(MatchBruteForce(cv::Mat(), train).empty());
  EXPECT_THROW(MatchBruteForce(cv::Mat(2, 16, CV_8UC1), train), std::invalid_argument);
}

TEST(MatchBruteForceTest, SingleTrainRowPassesRatioTest) {
  const std::vector<cv::DMatch> m = MatchBruteForce(Desc(3), Desc(0));
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].distance, 3.f);
  EXPECT_EQ(DescriptorDistance(Desc(3), Desc(0)), 3);
}

}  // namespace
}  // namespace ademono
