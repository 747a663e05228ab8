#include "ademono/eval/map_scale.h"

#include <gtest/gtest.h>

#include <cmath>

namespace ademono {
namespace {

// A sloped wall 2-4 m away and observations of it in a map 0.8x metric.
cv::Mat WallDepth() {
  cv::Mat depth(48, 64, CV_32FC1);
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u) depth.at<float>(v, u) = 2.0f + 2.0f * u / depth.cols;
  return depth;
}

std::vector<MapDepthObservation> Observations(const cv::Mat& depth, double map_from_metric) {
  std::vector<MapDepthObservation> out;
  for (int v = 2; v < depth.rows; v += 4)
    for (int u = 1; u < depth.cols; u += 3)
      out.push_back({Eigen::Vector2d(u + 0.3, v - 0.4), map_from_metric * depth.at<float>(v, u)});
  return out;
}

TEST(MapScaleTest, RecoversTheFactorFromTheMapToTheSensor) {
  const cv::Mat depth = WallDepth();
  const auto k = MeasureKeyFrameScale(7, Observations(depth, 0.8), depth);
  ASSERT_TRUE(k.has_value());
  EXPECT_EQ(k->frame, 7u);
  EXPECT_EQ(k->samples, 12u * 21u);
  EXPECT_NEAR(k->scale, 1.25, 1e-6);
}

TEST(MapScaleTest, ReadsTheNearestPixelAndSkipsMissingReadingsAndOutliers) {
  cv::Mat depth = WallDepth();
  std::vector<MapDepthObservation> obs = Observations(depth, 2.0);
  // No reading under a third of them; one in twelve occluded (a person 1 m away).
  for (size_t i = 0; i < obs.size(); i += 3)
    depth.at<float>(std::lround(obs[i].pixel.y()), std::lround(obs[i].pixel.x())) = 0;
  for (size_t i = 1; i < obs.size(); i += 12)
    depth.at<float>(std::lround(obs[i].pixel.y()), std::lround(obs[i].pixel.x())) = 1.0f;
  // Off the image, behind the camera, not finite: never read.
  obs.push_back({Eigen::Vector2d(-3, 5), 1.0});
  obs.push_back({Eigen::Vector2d(70, 5), 1.0});
  obs.push_back({Eigen::Vector2d(5, 5), -1.0});
  obs.push_back({Eigen::Vector2d(NAN, 5), 1.0});
  const auto k = MeasureKeyFrameScale(0, obs, depth);
  ASSERT_TRUE(k.has_value());
  EXPECT_EQ(k->samples, 252u - 84u) << "21 of them occluded";
  EXPECT_NEAR(k->scale, 0.5, 1e-6);
}

TEST(MapScaleTest, TooFewReadingsGiveNoMeasurement) {
  const cv::Mat depth = WallDepth();
  std::vector<MapDepthObservation> obs = Observations(depth, 1.0);
  obs.resize(19);
  EXPECT_FALSE(MeasureKeyFrameScale(0, obs, depth).has_value());
  EXPECT_TRUE(MeasureKeyFrameScale(0, obs, depth, 19).has_value());
  EXPECT_FALSE(MeasureKeyFrameScale(0, Observations(depth, 1.0), cv::Mat()).has_value());
  cv::Mat millimetres;
  depth.convertTo(millimetres, CV_16U, 1000);
  EXPECT_FALSE(MeasureKeyFrameScale(0, Observations(depth, 1.0), millimetres).has_value());
}

TEST(MapScaleTest, SummarySortsByFrameAndTakesPercentilesOverKeyframes) {
  EXPECT_FALSE(SummarizeMapScale({}).has_value());
  std::vector<KeyFrameMapScale> kfs;
  for (int i = 9; i >= 0; --i) kfs.push_back({static_cast<size_t>(i * 10), 100, 1.0 + 0.1 * i});
  const auto report = SummarizeMapScale(kfs);
  ASSERT_TRUE(report.has_value());
  EXPECT_EQ(report->per_keyframe.front().frame, 0u);
  EXPECT_EQ(report->per_keyframe.back().frame, 90u);
  EXPECT_NEAR(report->median, 1.45, 1e-12);
  EXPECT_NEAR(report->p10, 1.09, 1e-12);
  EXPECT_NEAR(report->p90, 1.81, 1e-12);
  const nlohmann::json j = report->ToJson();
  EXPECT_EQ(j["keyframes"].get<size_t>(), 10u);
  EXPECT_EQ(j["per_keyframe"][3]["frame"].get<size_t>(), 30u);
  EXPECT_NEAR(j["per_keyframe"][3]["scale"].get<double>(), 1.3, 1e-12);
}

}  // namespace
}  // namespace ademono
