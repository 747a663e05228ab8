#include "ademono/filter/enhancement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace ademono {
namespace {

TEST(EnhancementWeightTest, FormulaAndDegenerateDepths) {
  const cv::Point2f a(0, 0), b(3, 4);  // squared distance 25
  EXPECT_DOUBLE_EQ(EnhancementWeight(a, b, 5.f, 1.f, 9.f, 100, 100), 25 * std::exp(0.5));
  EXPECT_DOUBLE_EQ(EnhancementWeight(a, b, 9.f, 1.f, 9.f, 100, 100), 25 * std::exp(1.0));
  EXPECT_DOUBLE_EQ(EnhancementWeight(a, b, 1.f, 1.f, 9.f, 100, 100), 25.0);
  // P% and Q% scale the value only.
  EXPECT_DOUBLE_EQ(EnhancementWeight(a, b, 5.f, 1.f, 9.f, 50, 10), 25 * std::exp(0.5) * 0.05);
  // Unknown depth and an empty depth range rank by image distance alone.
  EXPECT_DOUBLE_EQ(EnhancementWeight(a, b, 0.f, 1.f, 9.f, 100, 100), 25.0);
  EXPECT_DOUBLE_EQ(
      EnhancementWeight(a, b, std::numeric_limits<float>::quiet_NaN(), 1.f, 9.f, 100, 100), 25.0);
  EXPECT_DOUBLE_EQ(EnhancementWeight(a, b, 4.f, 4.f, 4.f, 100, 100), 25.0);
  EXPECT_DOUBLE_EQ(DefaultPPercent(cv::Size(640, 480)), 100.0 / (640.0 * 640 + 480 * 480));
}

TEST(SelectInBlockTest, GreedyWalkFromNearestPoint) {
  // Start at p1 (depth 1). From p1: W(p0) = 100 e^0.5, W(p2) = 200 e, W(p3) = 82 e -> p2.
  // From p2: W(p0) = 100 e^0.5 = 164.9, W(p3) = 82 e = 222.9 -> p3. ceil(0.75 * 4) = 3 chosen.
  const std::vector<cv::Point2f> pts{{0, 0}, {10, 0}, {0, 10}, {1, 1}};
  const std::vector<float> depths{2, 1, 3, 3};
  EXPECT_EQ(SelectInBlock({0, 1, 2, 3}, pts, depths, 0.75, 100, 100), std::vector<int>({1, 2, 3}));
  // Without depths the walk starts at the first member and follows image distance:
  // from p0 the farthest is p2 (100, tie with p1 -> lower index p1), then from p1 p2 (200).
  EXPECT_EQ(SelectInBlock({0, 1, 2, 3}, pts, {}, 0.75, 100, 100), std::vector<int>({0, 1, 2}));
}

TEST(SelectInBlockTest, DepthBreaksDistanceTies) {
  // p1 and p2 are equally far from the start p0; the deeper p2 wins.
  const std::vector<cv::Point2f> pts{{0, 0}, {10, 0}, {0, 10}, {5, 5}};
  const std::vector<float> depths{1, 2, 3, 1};
  EXPECT_EQ(SelectInBlock({0, 1, 2, 3}, pts, depths, 0.5, 100, 100), std::vector<int>({0, 2}));
}

TEST(SelectInBlockTest, KeepCountRoundsUp) {
  std::vector<cv::Point2f> pts;
  for (int i = 0; i < 8; ++i)
    pts.emplace_back(static_cast<float>(i * 7 % 5), static_cast<float>(i));
  const std::vector<float> depths(8, 2.f);
  const int expected[9] = {0, 1, 2, 3, 3, 4, 5, 6, 6};  // ceil(0.75 n)
  for (int n = 0; n <= 8; ++n) {
    std::vector<int> members;
    for (int i = 0; i < n; ++i) members.push_back(i);
    EXPECT_EQ(static_cast<int>(SelectInBlock(members, pts, depths, 0.75, 100, 100).size()),
              expected[n])
        << "n = " << n;
  }
}

TEST(QuadtreeLeafBlocksTest, BlockNumbering) {
  const cv::Size size(100, 100);
  const std::vector<cv::Point2f> pts{{10, 10}, {60, 10}, {60, 60}, {10, 60}};
  EXPECT_EQ(QuadtreeLeafBlocks(pts, size, 1), std::vector<int>({0, 1, 2, 3}));
  EXPECT_EQ(QuadtreeLeafBlocks(pts, size, 0), std::vector<int>({0, 0, 0, 0}));
  const std::vector<cv::Point2f> fine{{10, 10}, {30, 10}, {30, 30},  {10, 30},
                                      {60, 60}, {99, 99}, {-5, 200}, {80, 10}};
  EXPECT_EQ(QuadtreeLeafBlocks(fine, size, 2), std::vector<int>({0, 1, 2, 3, 8, 10, 15, 5}));
}

TEST(SelectEnhancedFeaturesTest, SelectsPerLeafBlock) {
  const cv::Size size(400, 400);
  std::vector<cv::Point2f> pts;
  // One point in each of the 16 leaves (100 x 100 blocks) ...
  for (int by = 0; by < 4; ++by)
    for (int bx = 0; bx < 4; ++bx) pts.emplace_back(bx * 100.f + 50.f, by * 100.f + 50.f);
  // ... and four more in the top-left leaf (together with (50, 50)).
  pts.emplace_back(10.f, 10.f);  // 16
  pts.emplace_back(90.f, 10.f);  // 17
  pts.emplace_back(10.f, 90.f);  // 18
  pts.emplace_back(52.f, 52.f);  // 19
  std::vector<float> depths(pts.size(), 2.f);
  depths[16] = 1.f;  // the walk starts here
  depths[19] = 3.f;
  EnhancementParams params;  // 0.75, two levels
  std::vector<bool> kept = SelectEnhancedFeatures(pts, depths, {}, size, params);
  // Leaf 0 has 5 points: ceil(3.75) = 4 kept. From 16 (10,10) the farthest-deep is 19 (52,52):
  // d2 = 3528 * e vs 17/18: 6400 * e^0.5 = 10552 > 9590: 17 (lower index on the 17/18 tie).
  // From 17 (90,10): 18 d2 = 12800 e^0.5 beats 0 (50,50): 3200 e^0.5 and 19 (52,52): 3208 e.
  // Dropped: point 0 at (50, 50).
  for (size_t i = 0; i < pts.size(); ++i) EXPECT_EQ(kept[i], i != 0) << "point " << i;
  // Inactive points take no part and are reported not kept.
  std::vector<bool> active(pts.size(), true);
  active[19] = false;
  kept = SelectEnhancedFeatures(pts, depths, active, size, params);
  EXPECT_FALSE(kept[19]);
  int kept_leaf0 = 0;
  for (size_t i : {0u, 16u, 17u, 18u}) kept_leaf0 += kept[i] ? 1 : 0;
  EXPECT_EQ(kept_leaf0, 3);  // ceil(0.75 * 4)
  EXPECT_THROW(SelectEnhancedFeatures(pts, {1.f}, {}, size, params), std::invalid_argument);
}

}  // namespace
}  // namespace ademono
