#include "ademono/filter/feature_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "filter_test_util.h"

namespace ademono {
namespace {

using filter_test::TestCamera;

TEST(PointLabelNameTest, Names) {
  EXPECT_STREQ(PointLabelName(PointLabel::kKept), "kept");
  EXPECT_STREQ(PointLabelName(PointLabel::kEnhancementDropped), "enhancement_dropped");
  EXPECT_STREQ(PointLabelName(PointLabel::kDynamicSmallBox), "dynamic_small_box");
  EXPECT_STREQ(PointLabelName(PointLabel::kDynamicStage1), "dynamic_stage1");
  EXPECT_STREQ(PointLabelName(PointLabel::kDynamicStage2), "dynamic_stage2");
  EXPECT_STREQ(PointLabelName(PointLabel::kDistantDropped), "distant_dropped");
}

TEST(FilterOptionsTest, FromYamlAndCheck) {
  const FilterOptions o = FilterOptions::FromYaml(
      YAML::Load("{enable_enhancement: false, enhancement_levels: 1, box_growth: 0.05, "
                 "dynamic_class_ids: [0, 2], z_th_m: 20, drop_probability: 0.25, seed: 7, "
                 "stage1_motion_compensation: false}"));
  EXPECT_FALSE(o.enable_enhancement);
  EXPECT_TRUE(o.enable_dynamic_removal);
  EXPECT_EQ(o.enhancement_levels, 1);
  EXPECT_DOUBLE_EQ(o.dynamic.box_growth, 0.05);
  EXPECT_EQ(o.dynamic.dynamic_class_ids, std::vector<int>({0, 2}));
  EXPECT_DOUBLE_EQ(o.z_th_m, 20);
  EXPECT_DOUBLE_EQ(o.drop_probability, 0.25);
  EXPECT_EQ(o.seed, 7u);
  EXPECT_FALSE(o.dynamic.stage1_motion_compensation);
  EXPECT_TRUE(FilterOptions{}.dynamic.stage1_motion_compensation);
  EXPECT_DOUBLE_EQ(o.dynamic.d_dis_px, 8.0);  // default kept
  EXPECT_EQ(FilterOptions::FromYaml(YAML::Node()).dynamic.background_matches_t, 20);
  EXPECT_THROW(FilterOptions::FromYaml(YAML::Load("{drop_probability: 1.5}")),
               std::invalid_argument);
  EXPECT_THROW(FilterOptions::FromYaml(YAML::Load("{z_th_m: far}")), std::invalid_argument);
  EXPECT_THROW(FilterOptions::FromYaml(YAML::Load("{seed: -1}")), std::invalid_argument);
  EXPECT_THROW(FilterOptions::FromYaml(YAML::Load("{enhancement_levels: 1.5}")),
               std::invalid_argument);
  EXPECT_THROW(FilterOptions::FromYaml(YAML::Load("[1, 2]")), std::invalid_argument);
  EXPECT_THROW(FilterOptions::FromYaml(YAML::Load("{enhancement_keep_ratio: 0}")),
               std::invalid_argument);
  EXPECT_THROW(FilterOptions::FromYaml(YAML::Load("{dynamic_class_ids: person}")),
               std::invalid_argument);
  EXPECT_THROW(FilterOptions::FromYaml(YAML::Load("{stage1_motion_compensation: maybe}")),
               std::invalid_argument);
  EXPECT_EQ(
      FilterOptions::FromYaml(YAML::Load("{motion_min_inliers: 20}")).dynamic.motion_min_inliers,
      20);
  EXPECT_THROW(FilterOptions::FromYaml(YAML::Load("{motion_min_inliers: 3}")),
               std::invalid_argument);
  EXPECT_THROW(FilterOptions::FromYaml(YAML::Load("{motion_inlier_px: 0}")), std::invalid_argument);
  EXPECT_EQ(FilterOptions{}.dynamic.dynamic_test, "depth");
  const FilterOptions epipolar =
      FilterOptions::FromYaml(YAML::Load("{dynamic_test: epipolar, epipolar_px: 1.5}"));
  EXPECT_EQ(epipolar.dynamic.dynamic_test, "epipolar");
  EXPECT_DOUBLE_EQ(epipolar.dynamic.epipolar_px, 1.5);
  EXPECT_THROW(FilterOptions::FromYaml(YAML::Load("{dynamic_test: flow}")), std::invalid_argument);
  EXPECT_THROW(FilterOptions::FromYaml(YAML::Load("{epipolar_px: 0}")), std::invalid_argument);
  EXPECT_THROW(FilterOptions::FromYaml(YAML::Load("{motion_ransac_iterations: 0}")),
               std::invalid_argument);
  try {
    FilterOptions::FromYaml(YAML::Load("{d_dis: 5}"));  // misspelt d_dis_px
    ADD_FAILURE() << "unknown key accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "unknown key 'filter.d_dis'");
  }
  FilterOptions bad;
  bad.dynamic.background_matches_t = 0;
  EXPECT_THROW(FeatureFilter{bad}, std::invalid_argument);
}

// Keypoints on a regular grid, all 40 m deep except the given shallow ones.
struct Frame {
  Camera camera = TestCamera();
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  std::vector<float> depths;
  std::vector<Detection> detections;
  Frame() {
    std::mt19937 rng(1);
    for (int y = 20; y < 480; y += 40)
      for (int x = 20; x < 640; x += 40) keypoints.emplace_back(x, y, 31.f);
    descriptors = cv::Mat(static_cast<int>(keypoints.size()), 32, CV_8UC1);
    for (int r = 0; r < descriptors.rows; ++r)
      for (int c = 0; c < 32; ++c) descriptors.at<uchar>(r, c) = static_cast<uchar>(rng() & 0xFF);
    depths.assign(keypoints.size(), 5.f);
    for (size_t i = 0; i < depths.size(); i += 2) depths[i] = 40.f;
    Detection person;
    person.class_id = 0;
    person.class_name = "person";
    person.box = cv::Rect2f(10, 10, 40, 40);  // small; grown box holds the keypoint (20, 20) only
    detections.push_back(person);
  }
  FilterInput Input() const {
    FilterInput in;
    in.camera = &camera;
    in.keypoints = &keypoints;
    in.descriptors = &descriptors;
    in.depths = &depths;
    in.detections = &detections;
    return in;
  }
};

// The paper's small-box rule (drop every point inside), which these tests check.
FilterOptions PaperSmallBoxes() {
  FilterOptions o;
  o.dynamic.judge_small_boxes = false;
  return o;
}

TEST(FeatureFilterTest, FiltersApplyInOrderAndStatsAddUp) {
  const Frame f;
  FeatureFilter filter{PaperSmallBoxes()};
  FilterStats stats;
  const std::vector<PointLabel> labels = filter.Apply(f.Input(), &stats);
  ASSERT_EQ(labels.size(), f.keypoints.size());
  // 16 x 12 grid = 192 points, 12 per leaf block of 160 x 120: ceil(0.75 * 12) = 9 kept per leaf.
  EXPECT_EQ(stats.removed_enhancement, 16 * 3);
  EXPECT_EQ(stats.boxes_small, 1);
  EXPECT_EQ(stats.boxes_large, 0);
  EXPECT_EQ(stats.stage1_ran, 0);  // no large box, no previous frame
  EXPECT_EQ(stats.stage1_compensated, 0);
  // Grown box (8.9, 8.9)-(51.1, 51.1) holds (20, 20) only; it is removed unless enhancement dropped
  // it.
  const int small = labels[0] == PointLabel::kDynamicSmallBox ? 1 : 0;
  EXPECT_EQ(stats.removed_small_box, small);
  EXPECT_EQ(labels[0] == PointLabel::kEnhancementDropped || small == 1, true);
  int deep_survivors = 0;
  for (size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] == PointLabel::kDistantDropped) {
      EXPECT_GT(f.depths[i], 30.f);
    }
    if (f.depths[i] > 30.f &&
        (labels[i] == PointLabel::kKept || labels[i] == PointLabel::kDistantDropped))
      ++deep_survivors;
  }
  EXPECT_GT(stats.removed_distant, 0);
  EXPECT_LT(stats.removed_distant, deep_survivors);
  EXPECT_EQ(stats.kept + stats.removed_enhancement + stats.removed_small_box +
                stats.removed_stage1 + stats.removed_stage2 + stats.removed_distant,
            static_cast<int>(labels.size()));
}

TEST(FeatureFilterTest, SameSeedSameLabelsAcrossFilters) {
  const Frame f;
  FeatureFilter a{FilterOptions{}}, b{FilterOptions{}};
  for (int frame = 0; frame < 3; ++frame) EXPECT_EQ(a.Apply(f.Input()), b.Apply(f.Input()));
  // The engine advances between frames: a later frame draws differently.
  FeatureFilter c{FilterOptions{}};
  const std::vector<PointLabel> first = c.Apply(f.Input());
  EXPECT_NE(first, c.Apply(f.Input()));
}

TEST(FeatureFilterTest, AblationSwitches) {
  const Frame f;
  FilterOptions off = PaperSmallBoxes();
  off.enable_enhancement = off.enable_dynamic_removal = off.enable_distant_filter = false;
  FeatureFilter none{off};
  for (PointLabel l : none.Apply(f.Input())) EXPECT_EQ(l, PointLabel::kKept);
  FilterOptions dyn_only = off;
  dyn_only.enable_dynamic_removal = true;
  FilterStats stats;
  FeatureFilter dyn{dyn_only};
  const std::vector<PointLabel> labels = dyn.Apply(f.Input(), &stats);
  EXPECT_EQ(labels[0], PointLabel::kDynamicSmallBox);
  EXPECT_EQ(stats.removed_small_box, 1);
  EXPECT_EQ(stats.kept, static_cast<int>(labels.size()) - 1);
}

TEST(FeatureFilterTest, RejectsInconsistentInput) {
  const Frame f;
  FeatureFilter filter{FilterOptions{}};
  FilterInput in = f.Input();
  const std::vector<float> short_depths(3, 1.f);
  in.depths = &short_depths;
  EXPECT_THROW(filter.Apply(in), std::invalid_argument);
  in = f.Input();
  in.camera = nullptr;
  EXPECT_THROW(filter.Apply(in), std::invalid_argument);
  in = f.Input();
  in.keypoints = nullptr;
  EXPECT_THROW(filter.Apply(in), std::invalid_argument);
  // No depths at all: the distant filter has nothing to drop.
  in = f.Input();
  in.depths = nullptr;
  FilterStats stats;
  filter.Apply(in, &stats);
  EXPECT_EQ(stats.removed_distant, 0);
}

}  // namespace
}  // namespace ademono

namespace ademono {
namespace {

TEST(PointLabelTest, IsDynamicHoldsExactlyTheDynamicRemovalLabels) {
  int dynamic = 0;
  for (int label = 0; label < kNumPointLabels; ++label) {
    const PointLabel l = static_cast<PointLabel>(label);
    const std::string name = PointLabelName(l);
    EXPECT_EQ(IsDynamic(l), name.rfind("dynamic_", 0) == 0) << name;
    dynamic += IsDynamic(l);
  }
  EXPECT_EQ(dynamic, 4);
  EXPECT_FALSE(IsDynamic(PointLabel::kKept));
  EXPECT_FALSE(IsDynamic(PointLabel::kDistantDropped));
  EXPECT_TRUE(IsDynamic(PointLabel::kDynamicBoxVote));
}

}  // namespace
}  // namespace ademono
