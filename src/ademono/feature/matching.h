#pragma once
// Generic ORB matching helpers (after ORB-SLAM's matcher): Hamming distance (DescriptorDistance,
// declared in orb_extractor.h), the Hamming thresholds and rotation-consistency histogram that
// slam/matcher uses, and brute-force matching with a ratio test (the dynamic filter's stage 1).
// Window search over keypoints is FrameFeatures::FeaturesInArea (slam/frame.h).
//
// Contract: descriptors are CV_8UC1 with 32 columns, one row per keypoint (OrbExtractor's output).
// Every function is deterministic: ties are broken towards the lowest index.

#include <cstddef>
#include <opencv2/core.hpp>
#include <vector>

#include "ademono/feature/orb_extractor.h"

namespace ademono {

// ORB-SLAM's matching thresholds on the 256-bit Hamming distance.
inline constexpr int kOrbDistanceHigh = 100;
inline constexpr int kOrbDistanceLow = 50;

// Votes matches into bins of the keypoint angle change (30 bins of 12 degrees by default) and
// keeps the three most populated bins, as ORB-SLAM does: the second and third bins are kept only
// if they hold at least 10% of the first's votes. Matches outside the kept bins have inconsistent
// rotation and should be rejected.
class RotationHistogram {
 public:
  explicit RotationHistogram(int num_bins = 30);
  // Angles in degrees (cv::KeyPoint::angle); `match_index` is the caller's id for the match.
  void Add(float angle_from_deg, float angle_to_deg, int match_index);
  // Caller ids of matches outside the (up to) three dominant bins, in ascending order.
  std::vector<int> InconsistentMatches() const;
  // Caller ids inside the dominant bins, in ascending order.
  std::vector<int> ConsistentMatches() const;
  int NumBins() const { return static_cast<int>(bins_.size()); }

 private:
  std::vector<bool> DominantBins() const;
  std::vector<std::vector<int>> bins_;
};

struct BruteForceMatchOptions {
  // A match is kept if best < ratio * second best (Lowe's ratio test; 1 disables it).
  double ratio = 0.8;
  int max_distance = kOrbDistanceHigh;  // Hamming distance must be <= this
  // Keep only the best query per train descriptor (a one-to-one matching).
  bool unique_train = true;
};

// Matches every row of `query` against all rows of `train` (both CV_8UC1, 32 columns).
// DMatch::queryIdx / trainIdx index the rows; distance is the Hamming distance. Sorted by queryIdx.
std::vector<cv::DMatch> MatchBruteForce(const cv::Mat& query, const cv::Mat& train,
                                        const BruteForceMatchOptions& options = {});

}  // namespace ademono
