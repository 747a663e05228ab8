#pragma once
// A detector's recall against a synthetic sequence's ground-truth boxes (`ademono synth` writes
// detections.jsonl: a box per visible object of a dynamic COCO class). Per frame and class, true
// and detected boxes are paired greedily by IoU (highest first, each box used once); a true box
// counts as found when its pair has IoU >= min_iou. Frames are matched by name.

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ademono/perception/detection_io.h"

namespace ademono::synth {

struct ClassRecall {
  std::string class_name;
  long long truth = 0;     // ground-truth boxes
  long long found = 0;     // ... matched by a detection of the class with IoU >= min_iou
  long long detected = 0;  // detections of the class (matched or not)
  double Recall() const { return truth > 0 ? static_cast<double>(found) / truth : 0.0; }
};

struct RecallResult {
  std::map<int, ClassRecall> classes;  // by COCO class id
  long long frames = 0;                // frames with ground truth that were scored
  double min_iou = 0.5;
  nlohmann::ordered_json ToJson() const;
  std::string Markdown() const;  // "| class | boxes | found | recall | detections |" table
};

// `detected` frames without a ground-truth frame of the same name are ignored; ground-truth
// frames without detections count every true box as missed.
RecallResult DetectorRecall(const std::vector<FrameDetections>& truth,
                            const std::vector<FrameDetections>& detected, double min_iou = 0.5);

// IoU of two boxes (0 when either is empty).
double BoxIou(const cv::Rect2f& a, const cv::Rect2f& b);

}  // namespace ademono::synth
