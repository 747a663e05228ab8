#pragma once
// Detections cache: JSON lines, one object per frame, in frame order:
//   {"frame": 12, "timestamp": 0.4, "name": "frame-000012",
//    "detections": [{"class_id": 0, "class": "person", "score": 0.93,
//                    "box_xywh": [x, y, w, h]}]}
// Boxes are in original-image pixels. Frames are matched back by name, else by timestamp
// (within 1 ms), else by index. Synthetic sequences write this file with score 1.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "ademono/perception/detection.h"

namespace ademono {

struct FrameDetections {
  size_t frame = 0;
  double timestamp = 0.0;
  std::string name;
  std::vector<Detection> detections;
};

std::vector<FrameDetections> ReadDetectionsJsonl(const std::filesystem::path& path);
void WriteDetectionsJsonl(const std::filesystem::path& path,
                          const std::vector<FrameDetections>& frames);

// COCO class names in model order (80).
const std::vector<std::string>& CocoClassNames();

}  // namespace ademono
