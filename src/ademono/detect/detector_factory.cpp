#include "ademono/detect/detector_factory.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <stdexcept>

#include "ademono/core/error.h"
#include "ademono/core/options_table.h"
#include "ademono/detect/detection_io.h"
#include "ademono/detect/yolo_detector.h"
#include "ademono/dnn/model_arg.h"

namespace ademono {
namespace {

class NoDetector : public Detector {
 public:
  std::string Name() const override { return "none"; }
  std::vector<Detection> Detect(const FrameData&) override { return {}; }
};

// Detections read back from a JSON-lines cache, matched by frame name, else timestamp (1 ms),
// else index; only classes in `class_ids` (empty = all) are returned.
class CacheDetector : public Detector {
 public:
  CacheDetector(const std::filesystem::path& path, std::vector<int> class_ids)
      : path_(path), frames_(ReadDetectionsJsonl(path)), class_ids_(std::move(class_ids)) {
    for (size_t i = 0; i < frames_.size(); ++i) {
      if (!frames_[i].name.empty()) by_name_.emplace(frames_[i].name, i);
      by_time_.emplace(frames_[i].timestamp, i);
      by_index_.emplace(frames_[i].frame, i);
    }
  }
  std::string Name() const override { return "cache:" + path_.string(); }
  std::vector<Detection> Detect(const FrameData& frame) override {
    const FrameDetections& entry = frames_[Find(frame)];
    std::vector<Detection> detections;
    for (const auto& d : entry.detections) {
      if (class_ids_.empty() ||
          std::find(class_ids_.begin(), class_ids_.end(), d.class_id) != class_ids_.end()) {
        detections.push_back(d);
      }
    }
    return detections;
  }

 private:
  size_t Find(const FrameData& frame) const {
    if (!frame.name.empty()) {
      if (auto it = by_name_.find(frame.name); it != by_name_.end()) return it->second;
    }
    constexpr double kTolerance = 1e-3;
    auto it = by_time_.lower_bound(frame.timestamp - kTolerance);
    if (it != by_time_.end() && std::abs(it->first - frame.timestamp) <= kTolerance) {
      return it->second;
    }
    if (auto at = by_index_.find(frame.index); at != by_index_.end()) return at->second;
    ThrowInputError(path_, "no detections for frame " + std::to_string(frame.index) + " ('" +
                               frame.name + "', t=" + std::to_string(frame.timestamp) + ")");
  }

  std::filesystem::path path_;
  std::vector<FrameDetections> frames_;
  std::vector<int> class_ids_;
  std::map<std::string, size_t> by_name_;
  std::multimap<double, size_t> by_time_;
  std::map<size_t, size_t> by_index_;
};

}  // namespace

std::vector<int> ParseClassList(const std::string& text) {
  if (text == "all") return {};
  if (text == "dynamic") return DefaultDynamicClassIds();
  const auto& names = CocoClassNames();
  std::vector<int> ids;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = text.find(',', start);
    std::string item =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    start = comma == std::string::npos ? text.size() + 1 : comma + 1;
    while (!item.empty() && item.front() == ' ') item.erase(item.begin());
    while (!item.empty() && item.back() == ' ') item.pop_back();
    if (item.empty()) throw InputError("empty class name in '" + text + "'");
    int id = -1;
    if (std::all_of(item.begin(), item.end(), [](char c) { return std::isdigit(c); })) {
      id = item.size() <= 3 ? std::stoi(item) : -1;
      if (id < 0 || id >= static_cast<int>(names.size())) {
        throw InputError("class id " + item + " is outside the 80 COCO classes (0-79)");
      }
    } else {
      const auto it = std::find(names.begin(), names.end(), item);
      if (it == names.end()) {
        throw InputError("unknown class '" + item +
                         "' (expected a COCO class name or id, 'all' "
                         "or 'dynamic')");
      }
      id = static_cast<int>(it - names.begin());
    }
    if (std::find(ids.begin(), ids.end(), id) == ids.end()) ids.push_back(id);
  }
  return ids;
}

std::unique_ptr<Detector> MakeDetector(const std::string& spec, const DetectorOptions& options) {
  try {
    options.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  const size_t colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string argument = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (kind == "none" && colon == std::string::npos) return std::make_unique<NoDetector>();
  if (kind == "cache") {
    if (argument.empty()) throw InputError("detector 'cache' needs a file: cache:FILE.jsonl");
    return std::make_unique<CacheDetector>(argument, options.class_ids);
  }
  if (kind == "model") {
    const ModelArg model = ParseModelArg(argument, {"arch"});
    YoloArch arch = YoloArch::kAuto;
    if (auto it = model.options.find("arch"); it != model.options.end()) {
      try {
        arch = ParseYoloArch(it->second);
      } catch (const std::invalid_argument& e) {
        throw InputError(e.what());
      }
    }
    return std::make_unique<YoloDetector>(model.file, arch, options);
  }
  throw InputError(
      "unknown detector '" + spec +
      "' (expected none, cache:FILE.jsonl or model:FILE.onnx[,arch=yolox|yolov5|yolov8])");
}

}  // namespace ademono
