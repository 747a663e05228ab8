// Randomised inputs (fixed seeds): odd keypoint positions (outside the image, NaN), unknown and
// non-finite depths, boxes partly or fully outside the image, degenerate boxes, previous frames
// with missing world points. The filter must return one valid label per keypoint and keep its
// invariants; ASan/UBSan builds run this too.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "ademono/filter/feature_filter.h"

namespace ademono {
namespace {

TEST(FeatureFilterRobustnessTest, RandomInputsGiveValidLabels) {
  Camera camera;
  camera.width = 320;
  camera.height = 240;
  camera.fx = camera.fy = 300;
  camera.cx = 160;
  camera.cy = 120;
  camera.distortion = {0.05, -0.01, 0.001, 0.0, 0.0};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  FeatureFilter filter{FilterOptions{}};
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.2f, 1.2f), depth(-1.f, 60.f);
  for (int trial = 0; trial < 40; ++trial) {
    const int n = static_cast<int>(rng() % 300);
    std::vector<cv::KeyPoint> kps;
    std::vector<float> depths;
    cv::Mat desc(n, 32, CV_8UC1);
    for (int i = 0; i < n; ++i) {
      const bool weird = rng() % 50 == 0;
      kps.emplace_back(weird ? nan : u(rng) * 320, u(rng) * 240, 31.f);
      const int r = static_cast<int>(rng() % 20);
      depths.push_back(r == 0 ? nan : r == 1 ? std::numeric_limits<float>::infinity() : depth(rng));
      for (int c = 0; c < 32; ++c) desc.at<uchar>(i, c) = static_cast<uchar>(rng() & 0xFF);
    }
    std::vector<Detection> dets;
    for (int b = 0; b < static_cast<int>(rng() % 4); ++b) {
      Detection d;
      d.class_id = static_cast<int>(rng() % 8);
      d.box = cv::Rect2f(u(rng) * 320, u(rng) * 240, u(rng) * 200, u(rng) * 200);  // may be < 0
      dets.push_back(d);
    }
    PreviousFrameFeatures prev;
    prev.keypoints = kps;
    for (auto& kp : prev.keypoints) kp.pt.x += 2.f;
    prev.descriptors = desc.clone();
    for (int i = 0; i < n; ++i)
      prev.points_world.emplace_back(rng() % 3 == 0 ? Eigen::Vector3d::Constant(nan)
                                                    : Eigen::Vector3d(u(rng), u(rng), depth(rng)));
    FilterInput in;
    in.camera = &camera;
    in.keypoints = &kps;
    in.descriptors = &desc;
    in.depths = &depths;
    in.detections = &dets;
    in.previous = trial % 3 == 0 ? nullptr : &prev;
    if (trial % 2 == 0) in.predicted_cam_from_world = Rigid3d::Identity();
    FilterStats stats;
    const std::vector<PointLabel> labels = filter.Apply(in, &stats);
    ASSERT_EQ(labels.size(), kps.size());
    int removed_distant = 0;
    for (size_t i = 0; i < labels.size(); ++i) {
      ASSERT_LE(static_cast<int>(labels[i]), static_cast<int>(PointLabel::kDistantDropped));
      if (labels[i] == PointLabel::kDistantDropped) {
        ++removed_distant;
        EXPECT_TRUE(std::isfinite(depths[i]) && depths[i] > 30.f);
      }
    }
    EXPECT_EQ(removed_distant, stats.removed_distant);
    EXPECT_EQ(stats.kept + stats.removed_enhancement + stats.removed_small_box +
                  stats.removed_stage1 + stats.removed_stage2 + stats.removed_distant,
              n);
  }
}

}  // namespace
}  // namespace ademono
