#include "ademono/filter/visualize.h"

#include <gtest/gtest.h>

namespace ademono {
namespace {

cv::Vec3b At(const cv::Mat& img, int x, int y) { return img.at<cv::Vec3b>(y, x); }
cv::Vec3b Bgr(const cv::Scalar& s) {
  return cv::Vec3b(static_cast<uchar>(s[0]), static_cast<uchar>(s[1]), static_cast<uchar>(s[2]));
}

TEST(DrawFilterResultTest, ColoursPointsByLabelAndDrawsBoxes) {
  const cv::Mat grey(480, 640, CV_8UC1, cv::Scalar(0));
  // One point per label, in a row 50 px apart.
  std::vector<cv::KeyPoint> kps;
  std::vector<PointLabel> labels;
  for (int label = 0; label < kNumPointLabels; ++label) {
    kps.emplace_back(400.f + 50.f * static_cast<float>(label % 4), 300.f + 100.f * (label / 4),
                     31.f);
    labels.push_back(static_cast<PointLabel>(label));
  }
  Detection car;
  car.class_id = 2;
  car.class_name = "car";
  car.box = cv::Rect2f(300, 100, 200, 150);  // large
  const cv::Mat out = DrawFilterResult(grey, kps, labels, {car}, FilterOptions{});
  ASSERT_EQ(out.type(), CV_8UC3);
  ASSERT_EQ(out.size(), grey.size());
  // Filled discs for removed points, a ring for kept ones.
  for (size_t i = 1; i < kps.size(); ++i)
    EXPECT_EQ(At(out, cvRound(kps[i].pt.x), cvRound(kps[i].pt.y)), Bgr(PointLabelColor(labels[i])))
        << PointLabelName(labels[i]);
  EXPECT_EQ(At(out, 403, 300), Bgr(PointLabelColor(PointLabel::kKept)));
  EXPECT_EQ(At(out, 400, 300), cv::Vec3b(0, 0, 0));
  // Thick border of the grown box (d = 0.02 * 250 = 5): left edge at x = 295.
  EXPECT_NE(At(out, 295, 200), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(At(out, 320, 200), cv::Vec3b(0, 0, 0));
  // Distinct colours and names for every label.
  for (int a = 0; a < kNumPointLabels; ++a)
    for (int b = a + 1; b < kNumPointLabels; ++b)
      EXPECT_NE(Bgr(PointLabelColor(static_cast<PointLabel>(a))),
                Bgr(PointLabelColor(static_cast<PointLabel>(b))));
  for (int a = 0; a < kNumPointLabels; ++a)
    for (int b = a + 1; b < kNumPointLabels; ++b)
      EXPECT_STRNE(PointLabelName(static_cast<PointLabel>(a)),
                   PointLabelName(static_cast<PointLabel>(b)));
  for (int a = 0; a < kNumPointLabels; ++a)
    EXPECT_STRNE(PointLabelName(static_cast<PointLabel>(a)), "unknown");
  EXPECT_THROW(DrawFilterResult(grey, kps, {PointLabel::kKept}, {}, FilterOptions{}),
               std::invalid_argument);
  EXPECT_THROW(DrawFilterResult(cv::Mat(), {}, {}, {}, FilterOptions{}), std::invalid_argument);
}

}  // namespace
}  // namespace ademono
