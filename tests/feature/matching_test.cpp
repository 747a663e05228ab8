#include "ademono/feature/matching.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace ademono {
namespace {

cv::KeyPoint Kp(float x, float y, int octave = 0) {
  return cv::KeyPoint(x, y, 31.f, 0.f, 0.f, octave);
}

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

TEST(KeypointGridTest, WindowQueryMatchesBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> ux(-5.f, 645.f), uy(-5.f, 485.f);
  std::vector<cv::KeyPoint> kps;
  for (int i = 0; i < 500; ++i) kps.push_back(Kp(ux(rng), uy(rng), i % 8));
  const KeypointGrid grid(kps, cv::Size(640, 480), 10);
  EXPECT_EQ(grid.Size(), 500u);
  for (int q = 0; q < 50; ++q) {
    const float u = ux(rng), v = uy(rng), r = 5.f + q;
    const int min_level = q % 3 == 0 ? -1 : 2, max_level = q % 2 == 0 ? -1 : 5;
    std::vector<size_t> expected;
    for (size_t i = 0; i < kps.size(); ++i) {
      if (std::abs(kps[i].pt.x - u) > r || std::abs(kps[i].pt.y - v) > r) continue;
      if (min_level >= 0 && kps[i].octave < min_level) continue;
      if (max_level >= 0 && kps[i].octave > max_level) continue;
      expected.push_back(i);
    }
    EXPECT_EQ(grid.FeaturesInArea(u, v, r, min_level, max_level), expected) << "query " << q;
  }
}

TEST(KeypointGridTest, ExactCases) {
  const std::vector<cv::KeyPoint> kps{Kp(10, 10, 0), Kp(14, 10, 1), Kp(10, 16, 2),
                                      Kp(-3, 479, 0)};  // last one is left of the image
  const KeypointGrid grid(kps, cv::Size(640, 480));
  EXPECT_EQ(grid.FeaturesInArea(10, 10, 4), std::vector<size_t>({0, 1}));
  EXPECT_EQ(grid.FeaturesInArea(10, 10, 6), std::vector<size_t>({0, 1, 2}));
  EXPECT_EQ(grid.FeaturesInArea(10, 10, 6, 1, 1), std::vector<size_t>({1}));
  EXPECT_EQ(grid.FeaturesInArea(0, 480, 3), std::vector<size_t>({3}));
  EXPECT_TRUE(grid.FeaturesInArea(300, 300, 50).empty());
  EXPECT_EQ(grid.FeaturesInArea(10, 10, 1e30f).size(), 4u);  // huge radius: no overflow
  EXPECT_TRUE(grid.FeaturesInArea(std::nanf(""), 10, 5).empty());
  EXPECT_THROW(KeypointGrid(kps, cv::Size(0, 480)), std::invalid_argument);
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
