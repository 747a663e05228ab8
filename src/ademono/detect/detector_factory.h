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
  int num_threads = 1;
  void Check() const;
};

std::unique_ptr<Detector> MakeDetector(const std::string& spec, const DetectorOptions& options);

}  // namespace ademono
