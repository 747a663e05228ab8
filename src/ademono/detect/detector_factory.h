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
#include "ademono/perception/detector_options.h"

namespace ademono {

// "all" (-> empty), "dynamic" (-> DefaultDynamicClassIds()) or a comma-separated list of COCO
// class names and/or ids ("person,car", "0,2"). Throws InputError for an unknown name or bad id.
std::vector<int> ParseClassList(const std::string& text);

std::unique_ptr<Detector> MakeDetector(const std::string& spec, const DetectorOptions& options);

}  // namespace ademono
