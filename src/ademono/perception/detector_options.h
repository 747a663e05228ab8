#pragma once
// The `detector:` node of a config file (docs/slam.md): score_threshold, nms_iou, class_ids,
// class_agnostic_nms, num_threads. A plain options struct, here so that SLAM's config reader can
// check and write it without linking the ONNX detectors (detect/).

#include <yaml-cpp/yaml.h>

#include <vector>

#include "ademono/perception/detection.h"

namespace ademono {

template <typename Options>
class OptionsTable;

struct DetectorOptions {
  float score_threshold = 0.3f;
  float nms_iou = 0.45f;
  std::vector<int> class_ids = DefaultDynamicClassIds();  // empty = all 80 classes
  // false: class-aware NMS (boxes of different classes never suppress each other).
  // true: one NMS over all classes, as plain cv::dnn::NMSBoxes does (the YOLOX reference file).
  bool class_agnostic_nms = false;
  int num_threads = 1;
  void Check() const;  // throws std::invalid_argument
  // Strict reader of the `detector:` node (unknown keys rejected); absent keys keep defaults.
  // Throws std::invalid_argument naming the key (the caller adds the file).
  static DetectorOptions FromYaml(const YAML::Node& node);
  YAML::Node ToYaml() const;
  static const OptionsTable<DetectorOptions>& Table();
  bool operator==(const DetectorOptions&) const = default;
};

}  // namespace ademono
