#pragma once
// Builds a Detector from its command-line spec:
//   none                                       no detections
//   cache:FILE.jsonl                           detections read back (see detection_io.h)
//   model:FILE.onnx[,arch=yolox|yolov5|yolov8] an ONNX detector through ONNX Runtime
// Throws InputError for an unknown kind or a bad file.

#include <memory>
#include <string>
#include <vector>

#include "ademono/detect/detection.h"

namespace ademono {

struct DetectorOptions {
  float score_threshold = 0.3f;
  float nms_iou = 0.45f;
  std::vector<int> class_ids = DefaultDynamicClassIds();  // empty = all 80 classes
  // false: class-aware NMS (boxes of different classes never suppress each other).
  // true: one NMS over all classes, as plain cv::dnn::NMSBoxes does (the YOLOX reference file).
  bool class_agnostic_nms = false;
  int num_threads = 1;
  void Check() const;
};

// "all" (-> empty), "dynamic" (-> DefaultDynamicClassIds()) or a comma-separated list of COCO
// class names and/or ids ("person,car", "0,2"). Throws InputError for an unknown name or bad id.
std::vector<int> ParseClassList(const std::string& text);

std::unique_ptr<Detector> MakeDetector(const std::string& spec, const DetectorOptions& options);

}  // namespace ademono
