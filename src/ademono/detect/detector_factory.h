#pragma once
// Builds a Detector from its command-line spec:
//   none                                       no detections
//   cache:FILE.jsonl                           detections read back (see detection_io.h)
//   model:FILE.onnx[,arch=yolox|yolov5|yolov8] an ONNX detector through ONNX Runtime
// Throws InputError for an unknown kind or a bad file.

#include <yaml-cpp/yaml.h>

#include <memory>
#include <string>
#include <vector>

#include "ademono/detect/detection.h"

namespace ademono {

template <typename Options>
class OptionsTable;

// The `detector:` node of a config file (docs/slam.md): score_threshold, nms_iou, class_ids,
// class_agnostic_nms, num_threads.
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

// "all" (-> empty), "dynamic" (-> DefaultDynamicClassIds()) or a comma-separated list of COCO
// class names and/or ids ("person,car", "0,2"). Throws InputError for an unknown name or bad id.
std::vector<int> ParseClassList(const std::string& text);

std::unique_ptr<Detector> MakeDetector(const std::string& spec, const DetectorOptions& options);

}  // namespace ademono
