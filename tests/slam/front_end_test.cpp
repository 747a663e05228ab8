// FrontEnd::Filter hands tracking the keypoints the filters keep; with
// filter.distant_keep_bearing a distant-dropped keypoint goes on without its depth (a bearing
// that can match map points but makes none), without it the paper's rule removes it.
#include "ademono/slam/front_end.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "frame_test_util.h"

namespace ademono {
namespace {

ExtractedFrame FarAndNearKeypoints() {
  ExtractedFrame extracted;
  cv::RNG rng(3);
  for (int i = 0; i < 200; ++i) {
    extracted.keypoints.emplace_back(cv::Point2f(20.f + 3.f * i, 100.f + (i % 7) * 40.f), 7.f);
    extracted.depths.push_back(i % 2 == 0 ? 50.f : 10.f);  // half beyond z_th = 30 m
  }
  extracted.descriptors = cv::Mat(200, 32, CV_8UC1);
  rng.fill(extracted.descriptors, cv::RNG::UNIFORM, 0, 256);
  return extracted;
}

FilteredFrame FilterWith(bool keep_bearing) {
  SystemOptions options;
  options.depth.max_depth = 80.0;
  options.filter.enable_enhancement = false;
  options.filter.enable_dynamic_removal = false;
  options.filter.distant_keep_bearing = keep_bearing;
  FrontEnd front_end(testing_util::TestCamera(), options);
  return front_end.Filter(FarAndNearKeypoints(), {}, std::nullopt);
}

TEST(FrontEndTest, DistantDroppedKeypointsKeepTheirBearingOnlyWhenAsked) {
  const FilteredFrame removed = FilterWith(false), bearing = FilterWith(true);
  ASSERT_EQ(removed.labels, bearing.labels);  // the same seeded draw either way
  int kept = 0, dropped = 0;
  for (PointLabel label : removed.labels) {
    kept += label == PointLabel::kKept;
    dropped += label == PointLabel::kDistantDropped;
  }
  ASSERT_GT(dropped, 20);  // about half of the 100 far points
  ASSERT_LT(dropped, 80);
  EXPECT_EQ(removed.features->Size(), static_cast<size_t>(kept));
  ASSERT_EQ(bearing.features->Size(), static_cast<size_t>(kept + dropped));
  // In extraction order: the dropped ones without depth, the others with theirs.
  size_t k = 0;
  for (size_t i = 0; i < bearing.labels.size(); ++i) {
    if (bearing.labels[i] == PointLabel::kKept) {
      EXPECT_GT(bearing.features->depth[k], 0.f) << i;
      ++k;
    } else if (bearing.labels[i] == PointLabel::kDistantDropped) {
      EXPECT_LE(bearing.features->depth[k], 0.f) << i;
      ++k;
    }
  }
  EXPECT_EQ(bearing.num_with_depth, removed.num_with_depth);
}

}  // namespace
}  // namespace ademono
