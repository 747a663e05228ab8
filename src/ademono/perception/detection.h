#pragma once
// Object detections of the classes the dynamic filter cares about. Produced by an ONNX detector,
// a JSON-lines cache or synthetic ground truth.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "ademono/io/sequence.h"

namespace ademono {

struct Detection {
  int class_id = -1;  // COCO index (0 person, 1 bicycle, 2 car, 3 motorcycle, 5 bus, 7 truck)
  std::string class_name;
  float score = 0.f;
  cv::Rect2f box;  // x, y, w, h in original-image pixels
};

// COCO class ids of the default dynamic classes: person, bicycle, car, motorcycle, bus, truck.
inline const std::vector<int>& DefaultDynamicClassIds() {
  static const std::vector<int> ids{0, 1, 2, 3, 5, 7};
  return ids;
}

class Detector {
 public:
  virtual ~Detector() = default;
  virtual std::string Name() const = 0;
  // Deterministic; safe to call from a worker thread.
  virtual std::vector<Detection> Detect(const FrameData& frame) = 0;
};

}  // namespace ademono
