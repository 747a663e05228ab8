#include "ademono/feature/orb_extractor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <set>
#include <stdexcept>

#include "ademono/feature/matching.h"

namespace ademono {
namespace {

const char* kFrame0 = ADEMONO_SHARED_DIR "/data/7scenes-seq-a/frame-000000.color.jpg";

cv::Mat LoadFrame() {
  cv::Mat image = cv::imread(kFrame0, cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error(std::string("cannot read ") + kFrame0);
  return image;
}

struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
};

Features Extract(const cv::Mat& image, const OrbOptions& options = {},
                 const cv::Mat& mask = cv::Mat()) {
  Features f;
  OrbExtractor(options).Extract(image, f.keypoints, f.descriptors, mask);
  return f;
}

TEST(OrbExtractorTest, CountNearTargetOnRealImage) {
  const Features f = Extract(LoadFrame());
  RecordProperty("keypoints", static_cast<int>(f.keypoints.size()));
  EXPECT_GE(f.keypoints.size(), 900u);
  EXPECT_LE(f.keypoints.size(), 1100u);
  EXPECT_EQ(f.descriptors.rows, static_cast<int>(f.keypoints.size()));
  EXPECT_EQ(f.descriptors.cols, 32);
  EXPECT_EQ(f.descriptors.type(), CV_8UC1);
}

TEST(OrbExtractorTest, KeypointsFollowTheContract) {
  const cv::Mat image = LoadFrame();
  const OrbExtractor extractor{OrbOptions{}};
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  extractor.Extract(image, kps, desc);
  ASSERT_FALSE(kps.empty());
  for (const auto& kp : kps) {
    ASSERT_GE(kp.octave, 0);
    ASSERT_LT(kp.octave, 8);
    EXPECT_GE(kp.angle, 0.f);
    EXPECT_LT(kp.angle, 360.f);
    EXPECT_FLOAT_EQ(kp.size, 31.f * extractor.ScaleFactors()[kp.octave]);
    EXPECT_GE(kp.pt.x, 0.f);
    EXPECT_GE(kp.pt.y, 0.f);
    EXPECT_LT(kp.pt.x, image.cols);
    EXPECT_LT(kp.pt.y, image.rows);
  }
  EXPECT_FLOAT_EQ(extractor.ScaleFactors()[1], 1.2f);
  EXPECT_NEAR(extractor.LevelSigma2()[2], 1.44f * 1.44f, 1e-4);
  EXPECT_NEAR(extractor.InvLevelSigma2()[1], 1.f / 1.44f, 1e-6);
}

TEST(OrbExtractorTest, SpreadsOverTheImageAndUsesAllLevels) {
  const cv::Mat image = LoadFrame();
  const Features f = Extract(image);
  int grid[4][4] = {};
  std::set<int> levels;
  for (const auto& kp : f.keypoints) {
    const int gx = std::min(3, static_cast<int>(kp.pt.x * 4 / image.cols));
    const int gy = std::min(3, static_cast<int>(kp.pt.y * 4 / image.rows));
    ++grid[gy][gx];
    levels.insert(kp.octave);
  }
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) EXPECT_GT(grid[y][x], 5) << "grid cell " << x << "," << y;
  EXPECT_EQ(levels.size(), 8u);
  // Level 0 gets the largest share (geometric distribution over levels).
  int level0 = 0;
  for (const auto& kp : f.keypoints) level0 += kp.octave == 0 ? 1 : 0;
  EXPECT_GT(level0, 150);
}

TEST(OrbExtractorTest, WideKittiSizedImage) {
  // KITTI-like 1241 x 376 with 2000 features: several initial quadtree columns.
  cv::Mat wide;
  cv::resize(LoadFrame(), wide, cv::Size(1241, 376));
  OrbOptions options;
  options.num_features = 2000;
  const Features f = Extract(wide, options);
  EXPECT_GE(f.keypoints.size(), 1800u);
  EXPECT_LE(f.keypoints.size(), 2200u);
  int columns[8] = {};
  for (const auto& kp : f.keypoints)
    ++columns[std::min(7, static_cast<int>(kp.pt.x * 8 / wide.cols))];
  for (int c = 0; c < 8; ++c) EXPECT_GT(columns[c], 50) << "column " << c;
}

TEST(OrbExtractorTest, Deterministic) {
  const cv::Mat image = LoadFrame();
  const Features a = Extract(image), b = Extract(image);
  ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
  for (size_t i = 0; i < a.keypoints.size(); ++i) {
    EXPECT_EQ(a.keypoints[i].pt, b.keypoints[i].pt);
    EXPECT_EQ(a.keypoints[i].angle, b.keypoints[i].angle);
    EXPECT_EQ(a.keypoints[i].octave, b.keypoints[i].octave);
  }
  EXPECT_EQ(cv::norm(a.descriptors, b.descriptors, cv::NORM_HAMMING), 0.0);
}

TEST(OrbExtractorTest, OrientationMakesDescriptorsRotationInvariant) {
  const cv::Mat image = LoadFrame();
  cv::Mat rotated;
  cv::rotate(image, rotated, cv::ROTATE_90_CLOCKWISE);  // (x, y) -> (rows - 1 - y, x)
  const Features a = Extract(image), b = Extract(rotated);
  const std::vector<cv::DMatch> matches = MatchBruteForce(a.descriptors, b.descriptors);
  ASSERT_GT(matches.size(), 200u);
  int correct = 0;
  std::vector<float> angle_change;
  for (const auto& m : matches) {
    const cv::KeyPoint& ka = a.keypoints[m.queryIdx];
    const cv::KeyPoint& kb = b.keypoints[m.trainIdx];
    const cv::Point2f expected(static_cast<float>(image.rows - 1) - ka.pt.y, ka.pt.x);
    if (cv::norm(expected - kb.pt) < 3.0 * std::pow(1.2, ka.octave)) {
      ++correct;
      angle_change.push_back(std::fmod(kb.angle - ka.angle + 720.f, 360.f));
    }
  }
  RecordProperty("matches", static_cast<int>(matches.size()));
  RecordProperty("correct", correct);
  EXPECT_GT(correct, 0.8 * matches.size()) << correct << " of " << matches.size();
  // Rotating the image 90 degrees clockwise (y down) adds 90 degrees to every keypoint angle.
  std::sort(angle_change.begin(), angle_change.end());
  EXPECT_NEAR(angle_change[angle_change.size() / 2], 90.f, 2.f);
}

TEST(OrbExtractorTest, FallbackThresholdFindsFeaturesInLowContrast) {
  cv::Mat grey;
  cv::cvtColor(LoadFrame(), grey, cv::COLOR_BGR2GRAY);
  cv::Mat low;
  grey.convertTo(low, CV_8U, 0.12, 100);  // contrast compressed to ~30 grey levels
  OrbOptions no_fallback;
  no_fallback.min_fast_threshold = no_fallback.initial_fast_threshold;
  const size_t without = Extract(low, no_fallback).keypoints.size();
  const size_t with = Extract(low).keypoints.size();
  RecordProperty("with_fallback", static_cast<int>(with));
  RecordProperty("without_fallback", static_cast<int>(without));
  EXPECT_LT(without, 100u);
  EXPECT_GT(with, 300u);
  EXPECT_GT(with, 4 * without) << with << " vs " << without;
}

TEST(OrbExtractorTest, BlackAndEmptyImagesGiveNoFeatures) {
  for (const cv::Mat& image : {cv::Mat(480, 640, CV_8UC1, cv::Scalar(0)), cv::Mat(),
                               cv::Mat(10, 10, CV_8UC3, cv::Scalar(50, 60, 70))}) {
    const Features f = Extract(image);
    EXPECT_TRUE(f.keypoints.empty());
    EXPECT_EQ(f.descriptors.rows, 0);
    EXPECT_EQ(f.descriptors.cols, 32);
  }
}

TEST(OrbExtractorTest, RejectsUnsupportedImagesAndMasks) {
  const OrbExtractor extractor{OrbOptions{}};
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  EXPECT_THROW(extractor.Extract(cv::Mat(100, 100, CV_32FC1, cv::Scalar(0)), kps, desc),
               std::invalid_argument);
  EXPECT_THROW(extractor.Extract(cv::Mat(100, 100, CV_8UC1, cv::Scalar(0)), kps, desc,
                                 cv::Mat(50, 50, CV_8UC1, cv::Scalar(255))),
               std::invalid_argument);
}

TEST(OrbExtractorTest, MaskExcludesRegion) {
  const cv::Mat image = LoadFrame();
  cv::Mat mask(image.size(), CV_8UC1, cv::Scalar(255));
  mask(cv::Rect(0, 0, image.cols / 2, image.rows)).setTo(0);  // left half excluded
  const Features f = Extract(image, {}, mask);
  ASSERT_GT(f.keypoints.size(), 300u);
  for (const auto& kp : f.keypoints)
    EXPECT_GE(kp.pt.x, image.cols / 2 - 1.5f * std::pow(1.2f, kp.octave));
}

TEST(OrbOptionsTest, FromYamlReadsKeysAndKeepsDefaults) {
  const OrbOptions o =
      OrbOptions::FromYaml(YAML::Load("{num_features: 2000, scale_factor: 1.3, num_levels: 6}"));
  EXPECT_EQ(o.num_features, 2000);
  EXPECT_FLOAT_EQ(o.scale_factor, 1.3f);
  EXPECT_EQ(o.num_levels, 6);
  EXPECT_EQ(o.initial_fast_threshold, 20);
  EXPECT_EQ(o.min_fast_threshold, 7);
  EXPECT_EQ(OrbOptions::FromYaml(YAML::Node()).num_features, 1000);
}

TEST(OrbOptionsTest, RejectsBadValues) {
  EXPECT_THROW(OrbOptions::FromYaml(YAML::Load("{num_features: many}")), std::invalid_argument);
  EXPECT_THROW(OrbOptions::FromYaml(YAML::Load("{nfeatures: 2000}")), std::invalid_argument);
  EXPECT_THROW(OrbOptions::FromYaml(YAML::Load("{scale_factor: 1.0}")), std::invalid_argument);
  EXPECT_THROW(OrbOptions::FromYaml(YAML::Load("{num_levels: 0}")), std::invalid_argument);
  EXPECT_THROW(OrbOptions::FromYaml(YAML::Load("{min_fast_threshold: 30}")), std::invalid_argument);
  EXPECT_THROW(OrbOptions::FromYaml(YAML::Load("[1, 2]")), std::invalid_argument);
  OrbOptions bad;
  bad.num_features = 0;
  EXPECT_THROW(OrbExtractor{bad}, std::invalid_argument);
}

TEST(DescriptorDistanceTest, CountsDifferingBits) {
  cv::Mat a(1, 32, CV_8UC1, cv::Scalar(0)), b(1, 32, CV_8UC1, cv::Scalar(0));
  EXPECT_EQ(DescriptorDistance(a, b), 0);
  b.at<uchar>(0, 0) = 0xFF;
  b.at<uchar>(0, 31) = 0x01;
  EXPECT_EQ(DescriptorDistance(a, b), 9);
  b.setTo(0xFF);
  EXPECT_EQ(DescriptorDistance(a, b), 256);
}

}  // namespace
}  // namespace ademono

namespace ademono {
namespace {

TEST(OrbExtractorTest, OddSizesAndRandomMasksStayInContract) {
  const std::vector<cv::Size> sizes{{1, 1},    {38, 38},  {39, 39},  {40, 41},  {60, 45},
                                    {45, 300}, {700, 40}, {97, 131}, {320, 240}};
  cv::RNG rng(5);  // local generator: independent of other tests' use of cv::theRNG()
  for (const cv::Size& size : sizes) {
    cv::Mat image(size, CV_8UC1);
    rng.fill(image, cv::RNG::UNIFORM, 0, 256);
    cv::Mat mask(size, CV_8UC1);
    rng.fill(mask, cv::RNG::UNIFORM, 0, 2);
    for (const cv::Mat& m : {cv::Mat(), mask}) {
      const Features f = Extract(image, {}, m);
      ASSERT_EQ(f.descriptors.rows, static_cast<int>(f.keypoints.size())) << size;
      for (const auto& kp : f.keypoints) {
        EXPECT_GE(kp.pt.x, 0.f);
        EXPECT_GE(kp.pt.y, 0.f);
        EXPECT_LT(kp.pt.x, size.width);
        EXPECT_LT(kp.pt.y, size.height);
      }
      EXPECT_LE(f.keypoints.size(), 1010u);
    }
  }
}

}  // namespace
}  // namespace ademono
