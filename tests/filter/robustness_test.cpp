// Randomised inputs (fixed seeds): odd keypoint positions (outside the image, NaN), unknown and
// non-finite depths, boxes partly or fully outside the image, degenerate boxes, previous frames
// with missing world points. Every other trial also holds a large person box whose points partly
// moved 40 px since the previous frame and partly have no match, so that stage 1 and the box vote
// fire. The filter must return one valid label per keypoint, count every label in its stats and
// keep its invariants; ASan/UBSan builds run this too.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "ademono/filter/feature_filter.h"

namespace ademono {
namespace {

TEST(FeatureFilterRobustnessTest, RandomInputsGiveValidLabels) {
  Camera camera = Camera::Pinhole(320, 240, 300, 160, 120);
  camera.distortion = {0.05, -0.01, 0.001, 0.0, 0.0};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Both small-box rules: judged like large boxes and dropped whole (the paper's, the default).
  FilterOptions judging_options;
  judging_options.dynamic.judge_small_boxes = true;
  FeatureFilter judging{judging_options}, paper{FilterOptions{}};
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.2f, 1.2f), depth(-1.f, 60.f);
  std::array<int, kNumPointLabels> total{};  // over all trials, per label
  for (int trial = 0; trial < 40; ++trial) {
    const bool moving_box = trial % 2 == 1;
    const int n = static_cast<int>(rng() % 300) + (moving_box ? 100 : 0);
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
    const cv::Rect2f person_box(100, 40, 120, 160);  // 25% of the image: a large box
    if (moving_box) {
      Detection person;
      person.class_id = 0;
      person.box = person_box;
      dets.push_back(person);
    }
    PreviousFrameFeatures prev;
    prev.keypoints = kps;
    for (auto& kp : prev.keypoints) kp.pt.x += 2.f;
    prev.descriptors = desc.clone();
    for (int i = 0; i < n; ++i) {
      if (!moving_box || !person_box.contains(kps[i].pt)) continue;
      if (i % 3 == 0) prev.keypoints[i].pt.x += 40.f;  // moved: stage 1 fails it
      if (i % 3 == 1) prev.descriptors.row(i).setTo(cv::Scalar(i % 2 ? 0 : 255));  // unmatched
    }
    for (int i = 0; i < n; ++i)
      prev.points_world.emplace_back(rng() % 3 == 0 ? Eigen::Vector3d::Constant(nan)
                                                    : Eigen::Vector3d(u(rng), u(rng), depth(rng)));
    FilterInput in;
    in.camera = &camera;
    in.keypoints = &kps;
    in.descriptors = &desc;
    in.depths = &depths;
    in.detections = &dets;
    in.previous = trial % 3 == 0 && !moving_box ? nullptr : &prev;
    if (trial % 2 == 0) in.predicted_cam_from_world = Rigid3d::Identity();
    FilterStats stats;
    FeatureFilter& filter = trial % 4 < 2 ? judging : paper;
    const std::vector<PointLabel> labels = filter.Apply(in, &stats);
    ASSERT_EQ(labels.size(), kps.size());
    std::array<int, kNumPointLabels> count{};
    for (size_t i = 0; i < labels.size(); ++i) {
      const int label = static_cast<int>(labels[i]);
      ASSERT_GE(label, 0);
      ASSERT_LT(label, kNumPointLabels);
      ++count[label];
      ++total[label];
      if (labels[i] == PointLabel::kDistantDropped) {
        EXPECT_TRUE(std::isfinite(depths[i]) && depths[i] > 30.f);
      }
      if (IsDynamic(labels[i])) {
        EXPECT_FALSE(dets.empty());
      }
    }
    // Every label is counted in the stats, and the counts add up to every keypoint.
    EXPECT_EQ(count[static_cast<int>(PointLabel::kKept)], stats.kept);
    EXPECT_EQ(count[static_cast<int>(PointLabel::kEnhancementDropped)], stats.removed_enhancement);
    EXPECT_EQ(count[static_cast<int>(PointLabel::kDynamicSmallBox)], stats.removed_small_box);
    EXPECT_EQ(count[static_cast<int>(PointLabel::kDynamicStage1)], stats.removed_stage1);
    EXPECT_EQ(count[static_cast<int>(PointLabel::kDynamicStage2)], stats.removed_stage2);
    EXPECT_EQ(count[static_cast<int>(PointLabel::kDistantDropped)], stats.removed_distant);
    EXPECT_EQ(count[static_cast<int>(PointLabel::kDynamicBoxVote)], stats.removed_box_vote);
    EXPECT_EQ(stats.kept + stats.removed_enhancement + stats.removed_small_box +
                  stats.removed_stage1 + stats.removed_stage2 + stats.removed_box_vote +
                  stats.removed_distant,
              n);
  }
  // The inputs reach every label, so the checks above saw each of them at least once.
  for (int label = 0; label < kNumPointLabels; ++label)
    EXPECT_GT(total[label], 0) << PointLabelName(static_cast<PointLabel>(label));
}

}  // namespace
}  // namespace ademono
