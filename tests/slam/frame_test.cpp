#include "ademono/slam/frame.h"

#include <gtest/gtest.h>

#include <random>

#include "frame_test_util.h"

namespace ademono {
namespace {

using testing_util::TestFeatures;

TEST(FrameFeaturesTest, GridSearchAndVirtualRightCoordinate) {
  const auto f =
      TestFeatures({{100, 100}, {105, 102}, {300, 200}, {639, 479}}, {1.0f, -1.f, 2.0f, 0.f}, 1);
  EXPECT_EQ(f->FeaturesInArea(102, 101, 10), (std::vector<size_t>{0, 1}));
  EXPECT_EQ(f->FeaturesInArea(300, 200, 2), (std::vector<size_t>{2}));
  EXPECT_TRUE(f->FeaturesInArea(300, 200, 2, 1, 3).empty());  // all on level 0
  EXPECT_EQ(f->FeaturesInArea(638, 478, 4), (std::vector<size_t>{3}));
  EXPECT_NEAR(f->u_right[0], 100 - 585 * 0.08 / 1.0, 1e-3);
  EXPECT_LT(f->u_right[1], 0);
  EXPECT_LT(f->u_right[3], 0);
  EXPECT_TRUE(f->IsClose(0));
  EXPECT_FALSE(f->IsClose(1));
  const Eigen::Vector3d p = f->UnprojectCamera(2);
  EXPECT_NEAR(p.z(), 2.0, 1e-9);
  EXPECT_NEAR(p.x(), (300 - 320) * 2.0 / 585, 1e-9);
}

TEST(FrameFeaturesTest, GridSearchFindsExactlyWhatAScanOfEveryKeypointFinds) {
  // 2,000 keypoints on 8 levels, clustered like real corners and some on the image border, and
  // 3,000 windows of every size: the flat grid returns the brute-force answer in index order.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> ux(-2.f, 642.f), uy(-2.f, 482.f), jitter(-6.f, 6.f);
  std::uniform_int_distribution<int> octave(0, 7);
  std::vector<cv::KeyPoint> keypoints;
  for (int i = 0; i < 2000; ++i) {
    const float x = i % 3 == 0 && i > 0 ? keypoints[i - 1].pt.x + jitter(rng) : ux(rng);
    const float y = i % 3 == 0 && i > 0 ? keypoints[i - 1].pt.y + jitter(rng) : uy(rng);
    keypoints.emplace_back(cv::Point2f(x, y), 31.f, 0.f, 1.f, octave(rng));
  }
  cv::Mat descriptors(static_cast<int>(keypoints.size()), 32, CV_8UC1, cv::Scalar(0));
  auto pyramid = std::make_shared<ScalePyramid>(ScalePyramid::Make(8, 1.2f));
  const auto f = MakeFrameFeatures(testing_util::TestCamera(), pyramid, 0.08, 3.2, keypoints,
                                   descriptors, std::vector<float>(keypoints.size(), -1.f));
  std::uniform_real_distribution<float> radius(0.5f, 120.f);
  std::uniform_int_distribution<int> level(-1, 7);
  std::vector<size_t> reused;
  size_t found = 0;
  for (int q = 0; q < 3000; ++q) {
    const float u = ux(rng), v = uy(rng), r = radius(rng);
    const int lo = level(rng), hi = q % 4 == 0 ? -1 : level(rng);
    std::vector<size_t> expected;
    for (size_t i = 0; i < f->Size(); ++i) {
      const cv::KeyPoint& kp = f->keypoints_un[i];
      if (!f->InBounds(kp.pt.x, kp.pt.y)) continue;  // off the image: in no cell
      if ((lo >= 0 && kp.octave < lo) || (hi >= 0 && kp.octave > hi)) continue;
      if (std::abs(kp.pt.x - u) < r && std::abs(kp.pt.y - v) < r) expected.push_back(i);
    }
    ASSERT_EQ(f->FeaturesInArea(u, v, r, lo, hi), expected) << "window " << q;
    f->FeaturesInArea(u, v, r, lo, hi, &reused);
    ASSERT_EQ(reused, expected) << "window " << q << " into a reused buffer";
    found += expected.size();
  }
  EXPECT_GT(found, 50000u);  // the windows did find keypoints
}

}  // namespace
}  // namespace ademono
