#pragma once
// The map's metric scale measured against a depth sensor, keyframe by keyframe: for a map whose
// depths came from a network or from nothing (`--depth none`), the factor that takes the map's
// depths to the sensor's. It reads the map's scale where the map is, independent of the
// trajectory's shape. The scale of a sim3 alignment is not: Umeyama's estimate is the
// trajectory's spread against the ground truth's, so on a window whose camera moves 5 cm rms a
// shape error of 2 cm moves it by a quarter (docs/evaluation.md "The map's scale").

#include <Eigen/Core>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

namespace ademono {

// A map point seen by a keyframe: the keypoint's pixel (the image's own, distorted,
// coordinates, those of the sensor's depth image) and the point's depth in that keyframe's
// camera, in the map's units.
struct MapDepthObservation {
  Eigen::Vector2d pixel;
  double map_depth = 0;
};

struct KeyFrameMapScale {
  size_t frame = 0;    // the keyframe's input frame index
  size_t samples = 0;  // observations with a sensor reading
  double scale = 1;    // median of sensor depth / map depth over them
};

// `sensor_depth`: CV_32FC1 metres, 0 = no reading. The median ratio over the observations whose
// pixel has a reading (nearest pixel: a depth image's edges must not be blended); nullopt with
// fewer than `min_samples` of them.
std::optional<KeyFrameMapScale> MeasureKeyFrameScale(
    size_t frame, const std::vector<MapDepthObservation>& observations, const cv::Mat& sensor_depth,
    size_t min_samples = 20);

struct MapScaleReport {
  std::vector<KeyFrameMapScale> per_keyframe;  // by frame
  double median = 1, p10 = 1, p90 = 1;         // over the keyframes
  // {"keyframes", "median", "p10", "p90", "per_keyframe": [{"frame", "samples", "scale"}]}
  nlohmann::json ToJson() const;
};
// nullopt when no keyframe was measured.
std::optional<MapScaleReport> SummarizeMapScale(std::vector<KeyFrameMapScale> per_keyframe);

}  // namespace ademono
