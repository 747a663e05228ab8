// DetectGridFast (one FAST pass, scores, per-cell suppression) must return exactly what
// cv::FAST per cell returns, on real frames at every pyramid level, on noise, and on flat images.
#include "ademono/feature/grid_fast.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

namespace ademono {
namespace {

FastGrid GridFor(const cv::Mat& image) {
  // The ORB extractor's layout: 30-px cells over [16, size - 16).
  FastGrid g;
  g.min_x = 16, g.min_y = 16, g.max_x = image.cols - 16, g.max_y = image.rows - 16;
  const int width = g.max_x - g.min_x, height = g.max_y - g.min_y;
  g.num_cols = std::max(1, width / 30), g.num_rows = std::max(1, height / 30);
  g.cell_w = static_cast<int>(std::ceil(static_cast<double>(width) / g.num_cols));
  g.cell_h = static_cast<int>(std::ceil(static_cast<double>(height) / g.num_rows));
  return g;
}

void ExpectSame(const cv::Mat& image, int initial, int low, const std::string& what) {
  const FastGrid grid = GridFor(image);
  const auto expected = DetectGridFastReference(image, grid, initial, low);
  const auto actual = DetectGridFast(image, grid, initial, low);
  ASSERT_EQ(actual.size(), expected.size()) << what;
  for (size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(actual[i].pt, expected[i].pt) << what << " #" << i;
    ASSERT_EQ(actual[i].response, expected[i].response) << what << " #" << i;
    ASSERT_EQ(actual[i].size, expected[i].size);
    ASSERT_EQ(actual[i].angle, expected[i].angle);
    ASSERT_EQ(actual[i].octave, expected[i].octave);
  }
}

TEST(GridFastTest, MatchesPerCellFastOnRealFramesAtEveryLevel) {
  size_t total = 0;
  for (int frame : {0, 300}) {
    char path[512];
    std::snprintf(path, sizeof(path), "%s/data/7scenes-seq-a/frame-%06d.color.jpg",
                  ADEMONO_SHARED_DIR, frame);
    cv::Mat level = cv::imread(path, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(level.empty()) << path;
    for (int l = 0; l < 6; ++l) {
      ExpectSame(level, 20, 7, std::string(path) + " level " + std::to_string(l));
      total += DetectGridFastReference(level, GridFor(level), 20, 7).size();
      cv::resize(level, level, cv::Size(), 1 / 1.2, 1 / 1.2, cv::INTER_LINEAR);
    }
  }
  EXPECT_GT(total, 1000u);  // the comparison saw plenty of corners
}

TEST(GridFastTest, MatchesPerCellFastOnNoiseFlatAndEqualThresholds) {
  std::mt19937 rng(4);
  cv::Mat noise(200, 260, CV_8UC1);
  for (int y = 0; y < noise.rows; ++y)
    for (int x = 0; x < noise.cols; ++x) noise.at<uchar>(y, x) = static_cast<uchar>(rng() % 256);
  ExpectSame(noise, 20, 7, "noise");
  ExpectSame(noise, 60, 60, "noise, one threshold");
  ExpectSame(noise, 200, 1, "noise, extreme thresholds");
  cv::Mat blurred;
  cv::GaussianBlur(noise, blurred, cv::Size(5, 5), 1.5);
  ExpectSame(blurred, 20, 7, "blurred noise");
  ExpectSame(cv::Mat(120, 150, CV_8UC1, cv::Scalar(90)), 20, 7, "flat");
  // A roi (non-continuous rows) works the same.
  ExpectSame(noise(cv::Rect(10, 5, 200, 150)), 20, 7, "roi");
}

}  // namespace
}  // namespace ademono
