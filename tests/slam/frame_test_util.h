#pragma once
// Hand-made frame features for the frame, map and matcher tests: keypoints at given pixels (level
// 0, angle 10 * i unless given) with random descriptors that repeat for the same seed.

#include <memory>
#include <vector>

#include "ademono/slam/frame.h"

namespace ademono::testing_util {

// The 7-Scenes intrinsics.
inline Camera TestCamera() { return Camera::Pinhole(640, 480, 585, 320, 240); }

inline std::shared_ptr<const FrameFeatures> TestFeatures(const std::vector<cv::Point2f>& points,
                                                         const std::vector<float>& depth,
                                                         uint8_t seed,
                                                         const std::vector<float>& angles = {}) {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors(static_cast<int>(points.size()), 32, CV_8UC1);
  for (size_t i = 0; i < points.size(); ++i) {
    keypoints.emplace_back(points[i], 31.f, angles.empty() ? 10.f * i : angles[i], 1.f, 0);
    // The same (seed, i) always gives the same random descriptor.
    cv::RNG rng(1000 * seed + i);
    cv::Mat row = descriptors.row(static_cast<int>(i));
    rng.fill(row, cv::RNG::UNIFORM, 0, 256);
  }
  auto pyramid = std::make_shared<ScalePyramid>(ScalePyramid::Make(8, 1.2f));
  return MakeFrameFeatures(TestCamera(), pyramid, 0.08, 3.2, keypoints, descriptors, depth);
}

}  // namespace ademono::testing_util
