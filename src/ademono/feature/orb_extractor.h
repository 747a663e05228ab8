#pragma once
// ORB features as SLAM needs them (after ORB-SLAM's extractor): an image pyramid, FAST with a
// lower fallback threshold in weak texture, keypoints spread evenly on every level by a quadtree,
// intensity-centroid orientation and 256-bit rBRIEF descriptors.
//
// Contract: keypoints are in level-0 pixel coordinates (pt scaled up), `octave` is the pyramid
// level, `angle` in degrees [0, 360), `size` = patch size * scale of the level. Descriptors are
// CV_8UC1 rows of 32 bytes, one per keypoint. Deterministic for the same image.

#include <vector>

#include <opencv2/core.hpp>
#include <yaml-cpp/yaml.h>

namespace ademono {

template <typename Options>
class OptionsTable;

struct OrbOptions {
  int num_features = 1000;
  float scale_factor = 1.2f;
  int num_levels = 8;
  int initial_fast_threshold = 20;
  int min_fast_threshold = 7;
  void Check() const;  // throws std::invalid_argument
  // Reads the `orb:` sub-node; absent keys keep their defaults.
  static OrbOptions FromYaml(const YAML::Node& node);
  YAML::Node ToYaml() const;
  static const OptionsTable<OrbOptions>& Table();  // the keys of `orb:` (core/options_table.h)
  bool operator==(const OrbOptions&) const = default;
};

class OrbExtractor {
 public:
  explicit OrbExtractor(const OrbOptions& options);
  // `image` is CV_8UC1 or CV_8UC3 (converted to grey). `mask` (optional, CV_8UC1) excludes pixels.
  void Extract(const cv::Mat& image, std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors,
               const cv::Mat& mask = cv::Mat()) const;

  const OrbOptions& Options() const { return options_; }
  const std::vector<float>& ScaleFactors() const { return scale_factors_; }
  const std::vector<float>& LevelSigma2() const { return level_sigma2_; }
  const std::vector<float>& InvLevelSigma2() const { return inv_level_sigma2_; }

 private:
  OrbOptions options_;
  std::vector<float> scale_factors_, level_sigma2_, inv_level_sigma2_;
  std::vector<int> features_per_level_;
};

// Hamming distance between two 32-byte descriptors (rows of CV_8U).
int DescriptorDistance(const cv::Mat& a, const cv::Mat& b);
// The same on two raw 32-byte rows (no cv::Mat headers in hot loops).
int DescriptorDistance(const uchar* a, const uchar* b);

}  // namespace ademono
