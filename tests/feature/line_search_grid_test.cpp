#include "ademono/feature/line_search_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace ademono {
namespace {

// Every keypoint within the radius of the line, by brute force.
std::vector<size_t> WithinBand(const std::vector<cv::KeyPoint>& keypoints,
                               const std::vector<size_t>& indices, const Eigen::Vector3d& line,
                               double radius) {
  std::vector<size_t> near;
  for (size_t i : indices) {
    const double e = line.x() * keypoints[i].pt.x + line.y() * keypoints[i].pt.y + line.z();
    if (std::abs(e) / line.head<2>().norm() < radius) near.push_back(i);
  }
  return near;
}

TEST(LineSearchGridTest, FindsEveryKeypointNearAnyLineOnce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-20.f, 1260.f), v(-10.f, 390.f);
  std::vector<cv::KeyPoint> keypoints(2000);
  for (auto& kp : keypoints) kp.pt = cv::Point2f(u(rng), v(rng));
  std::vector<size_t> indices;  // every third keypoint is bucketed
  for (size_t i = 0; i < keypoints.size(); i += 3) indices.push_back(i);
  const LineSearchGrid grid(keypoints, indices);

  std::uniform_real_distribution<double> angle(0.0, M_PI), offset(-200.0, 1400.0);
  std::vector<size_t> found;
  size_t tested = 0, candidates = 0;
  for (int trial = 0; trial < 500; ++trial) {
    // Lines of every direction, including exactly horizontal and vertical ones.
    const double theta = trial == 0 ? 0.0 : trial == 1 ? M_PI / 2 : angle(rng);
    const Eigen::Vector3d line(std::cos(theta), std::sin(theta), -offset(rng));
    const double radius = trial % 2 ? 7.0 : 1.5;
    grid.Near(line * 3.7, radius, &found);  // the line's scale must not matter
    std::sort(found.begin(), found.end());
    ASSERT_EQ(std::adjacent_find(found.begin(), found.end()), found.end());
    const std::vector<size_t> exact = WithinBand(keypoints, indices, line, radius);
    ASSERT_TRUE(std::includes(found.begin(), found.end(), exact.begin(), exact.end()))
        << "trial " << trial;
    for (size_t i : found) ASSERT_EQ(i % 3, 0u);  // only bucketed keypoints
    tested += exact.size();
    candidates += found.size();
  }
  // The superset is a band of whole cells, not the whole image.
  EXPECT_GT(tested, 0u);
  EXPECT_LT(candidates, 500 * indices.size() / 5);
}

TEST(LineSearchGridTest, EmptyAndDegenerateInputsFindNothing) {
  std::vector<cv::KeyPoint> keypoints(4);
  std::vector<size_t> found{7};
  LineSearchGrid({}, {}).Near(Eigen::Vector3d(1, 0, -5), 3.0, &found);
  EXPECT_TRUE(found.empty());
  const LineSearchGrid grid(keypoints, {0, 1, 2, 3});  // all at the origin
  grid.Near(Eigen::Vector3d(0, 0, 1), 3.0, &found);    // no line at all
  EXPECT_TRUE(found.empty());
  grid.Near(Eigen::Vector3d(1, 0, 0), 1.0, &found);  // through the origin
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found, std::vector<size_t>({0, 1, 2, 3}));
  // A far outlier keeps the grid small and is still found; infinite bounds: one cell.
  keypoints[3].pt = cv::Point2f(1e30f, 5.f);
  const LineSearchGrid far(keypoints, {0, 1, 2, 3});
  far.Near(Eigen::Vector3d(0, 1, -5), 1.0, &found);  // the row v = 5
  EXPECT_EQ(std::count(found.begin(), found.end(), 3u), 1);
  far.Near(Eigen::Vector3d(1, 0, -2e30), 1.0, &found);  // the column u = 2e30: nobody there
  EXPECT_TRUE(found.empty());
  keypoints[3].pt = cv::Point2f(INFINITY, 5.f);
  const LineSearchGrid infinite(keypoints, {0, 1, 2, 3});
  infinite.Near(Eigen::Vector3d(0, 1, -5), 1.0, &found);
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found, std::vector<size_t>({0, 1, 2, 3}));
}

}  // namespace
}  // namespace ademono
