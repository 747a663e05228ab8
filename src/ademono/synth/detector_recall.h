#pragma once
// A detector's recall against a synthetic sequence's ground-truth boxes (`ademono synth` writes
// detections.jsonl: a box per visible object of a dynamic COCO class). Per frame and class, true
// and detected boxes are paired greedily by IoU (highest first, each box used once); a true box
// counts as found when its pair has IoU >= min_iou. Frames are matched by name. A car boxed as a
// bus or truck counts as found (the three are one class here): COCO detectors confuse them, and
// any of them removes the object's points. The per-class table keeps the detected class.

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
  // By the label given to each true box (e.g. the object's name), when labels were given;
  // `detected` is not counted here.
  std::map<std::string, ClassRecall> groups;
  long long frames = 0;                // frames with ground truth that were scored
  double min_iou = 0.5;
  nlohmann::ordered_json ToJson() const;
  std::string Markdown() const;  // "| class | boxes | found | recall | detections |" table
};

// `detected` frames without a ground-truth frame of the same name are ignored; ground-truth
// frames without detections count every true box as missed. `labels`, when given, holds a
// label per true box (labels[f][i] for truth[f].detections[i]) for RecallResult::groups.
RecallResult DetectorRecall(const std::vector<FrameDetections>& truth,
                            const std::vector<FrameDetections>& detected, double min_iou = 0.5,
                            const std::vector<std::vector<std::string>>* labels = nullptr);

// The class a box is matched as: bus (5) and truck (7) as car (2), others as themselves.
int RecallClass(int class_id);

// IoU of two boxes (0 when either is empty).
double BoxIou(const cv::Rect2f& a, const cv::Rect2f& b);

}  // namespace ademono::synth
