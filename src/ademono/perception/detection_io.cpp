#include "ademono/perception/detection_io.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"

namespace ademono {

namespace {

using nlohmann::json;

// The shortest decimal that reads back as the same float, as a double, so the file shows
// "0.93" rather than 0.9300000071525574 and still round-trips exactly.
double FloatForJson(float value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  double out = 0.0;
  std::from_chars(buffer, result.ptr, out);
  return out;
}

const json& RequireMember(const json& object, const char* key, const std::filesystem::path& path,
                          size_t line) {
  const auto it = object.find(key);
  if (it == object.end()) ThrowInputError(path, line, std::string("missing \"") + key + "\"");
  return *it;
}

double RequireFiniteNumber(const json& value, const std::string& what,
                           const std::filesystem::path& path, size_t line) {
  if (!value.is_number()) ThrowInputError(path, line, what + " is not a number");
  const double number = value.get<double>();
  if (!std::isfinite(number)) ThrowInputError(path, line, what + " is not finite");
  return number;
}

Detection ParseDetection(const json& item, size_t index, const std::filesystem::path& path,
                         size_t line) {
  const std::string where = "detection " + std::to_string(index);
  if (!item.is_object()) ThrowInputError(path, line, where + " is not an object");
  Detection detection;
  const json& class_id = RequireMember(item, "class_id", path, line);
  if (!class_id.is_number_integer() || class_id.get<int64_t>() < 0 ||
      class_id.get<int64_t>() >= static_cast<int64_t>(CocoClassNames().size())) {
    ThrowInputError(path, line, where + ": \"class_id\" must be an integer in [0, 80)");
  }
  detection.class_id = class_id.get<int>();
  if (const auto it = item.find("class"); it != item.end()) {
    if (!it->is_string()) ThrowInputError(path, line, where + ": \"class\" is not a string");
    detection.class_name = it->get<std::string>();
  } else {
    detection.class_name = CocoClassNames()[detection.class_id];
  }
  const double score = RequireFiniteNumber(RequireMember(item, "score", path, line),
                                           where + ": \"score\"", path, line);
  if (score < 0.0 || score > 1.0) {
    ThrowInputError(path, line, where + ": \"score\" must be in [0, 1]");
  }
  detection.score = static_cast<float>(score);
  const json& box = RequireMember(item, "box_xywh", path, line);
  if (!box.is_array() || box.size() != 4) {
    ThrowInputError(path, line, where + ": \"box_xywh\" must be an array of 4 numbers");
  }
  double xywh[4];
  for (size_t k = 0; k < 4; ++k) {
    xywh[k] = RequireFiniteNumber(box[k], where + ": \"box_xywh\"[" + std::to_string(k) + "]", path,
                                  line);
  }
  if (xywh[2] < 0.0 || xywh[3] < 0.0) {
    ThrowInputError(path, line, where + ": box width and height must be >= 0");
  }
  detection.box = cv::Rect2f(static_cast<float>(xywh[0]), static_cast<float>(xywh[1]),
                             static_cast<float>(xywh[2]), static_cast<float>(xywh[3]));
  return detection;
}

FrameDetections ParseFrameLine(const std::string& text, const std::filesystem::path& path,
                               size_t line) {
  json object;
  try {
    object = json::parse(text);
  } catch (const json::exception& e) {
    // A syntax error, or a number beyond a double (out_of_range.406, found by fuzzing).
    // nlohmann's message starts with "[json.exception.parse_error.101] "; keep what follows.
    std::string message = e.what();
    if (const auto pos = message.find("] "); pos != std::string::npos) message.erase(0, pos + 2);
    ThrowInputError(path, line, "not valid JSON: " + message);
  }
  if (!object.is_object()) ThrowInputError(path, line, "expected a JSON object per line");

  FrameDetections frame;
  const json& index = RequireMember(object, "frame", path, line);
  if (!index.is_number_integer() || index.get<int64_t>() < 0) {
    ThrowInputError(path, line, "\"frame\" must be a non-negative integer");
  }
  frame.frame = static_cast<size_t>(index.get<int64_t>());
  if (const auto it = object.find("timestamp"); it != object.end()) {
    frame.timestamp = RequireFiniteNumber(*it, "\"timestamp\"", path, line);
  }
  if (const auto it = object.find("name"); it != object.end()) {
    if (!it->is_string()) ThrowInputError(path, line, "\"name\" is not a string");
    frame.name = it->get<std::string>();
  }
  const json& detections = RequireMember(object, "detections", path, line);
  if (!detections.is_array()) ThrowInputError(path, line, "\"detections\" is not an array");
  frame.detections.reserve(detections.size());
  for (size_t i = 0; i < detections.size(); ++i) {
    frame.detections.push_back(ParseDetection(detections[i], i, path, line));
  }
  return frame;
}

}  // namespace

std::vector<FrameDetections> ReadDetectionsJsonl(const std::filesystem::path& path) {
  const std::string content = ReadTextFile(path);
  std::vector<FrameDetections> frames;
  std::istringstream in(content);
  std::string text;
  size_t line = 0;
  while (std::getline(in, text)) {
    ++line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (text.find_first_not_of(" \t") == std::string::npos) continue;
    FrameDetections frame = ParseFrameLine(text, path, line);
    // Frame order is part of the format: matching by index relies on it.
    if (!frames.empty() && frame.frame <= frames.back().frame) {
      ThrowInputError(path, line,
                      "frame " + std::to_string(frame.frame) + " does not follow frame " +
                          std::to_string(frames.back().frame) + " (frames must increase)");
    }
    frames.push_back(std::move(frame));
  }
  if (frames.empty()) ThrowInputError(path, "no frames (empty detections file)");
  return frames;
}

void WriteDetectionsJsonl(const std::filesystem::path& path,
                          const std::vector<FrameDetections>& frames) {
  for (size_t i = 1; i < frames.size(); ++i) {
    if (frames[i].frame <= frames[i - 1].frame) {
      throw std::invalid_argument("WriteDetectionsJsonl: frames must be in increasing order");
    }
  }
  WriteFileAtomic(path, [&](std::ostream& out) {
    for (const FrameDetections& frame : frames) {
      // ordered_json keeps the documented key order, which makes the file easy to read.
      nlohmann::ordered_json detections = nlohmann::ordered_json::array();
      for (const Detection& detection : frame.detections) {
        nlohmann::ordered_json item;
        item["class_id"] = detection.class_id;
        item["class"] = detection.class_name;
        item["score"] = FloatForJson(detection.score);
        item["box_xywh"] = {FloatForJson(detection.box.x), FloatForJson(detection.box.y),
                            FloatForJson(detection.box.width), FloatForJson(detection.box.height)};
        detections.push_back(std::move(item));
      }
      nlohmann::ordered_json object;
      object["frame"] = frame.frame;
      object["timestamp"] = frame.timestamp;
      object["name"] = frame.name;
      object["detections"] = detections;
      out << object.dump() << '\n';
    }
  });
}

const std::vector<std::string>& CocoClassNames() {
  // COCO 2017 names as used by YOLOX/Ultralytics (darknet's coco.names spells a few differently,
  // e.g. "motorbike"; the class ids are the same).
  static const std::vector<std::string> names{"person",        "bicycle",      "car",
                                              "motorcycle",    "airplane",     "bus",
                                              "train",         "truck",        "boat",
                                              "traffic light", "fire hydrant", "stop sign",
                                              "parking meter", "bench",        "bird",
                                              "cat",           "dog",          "horse",
                                              "sheep",         "cow",          "elephant",
                                              "bear",          "zebra",        "giraffe",
                                              "backpack",      "umbrella",     "handbag",
                                              "tie",           "suitcase",     "frisbee",
                                              "skis",          "snowboard",    "sports ball",
                                              "kite",          "baseball bat", "baseball glove",
                                              "skateboard",    "surfboard",    "tennis racket",
                                              "bottle",        "wine glass",   "cup",
                                              "fork",          "knife",        "spoon",
                                              "bowl",          "banana",       "apple",
                                              "sandwich",      "orange",       "broccoli",
                                              "carrot",        "hot dog",      "pizza",
                                              "donut",         "cake",         "chair",
                                              "couch",         "potted plant", "bed",
                                              "dining table",  "toilet",       "tv",
                                              "laptop",        "mouse",        "remote",
                                              "keyboard",      "cell phone",   "microwave",
                                              "oven",          "toaster",      "sink",
                                              "refrigerator",  "book",         "clock",
                                              "vase",          "scissors",     "teddy bear",
                                              "hair drier",    "toothbrush"};
  return names;
}

}  // namespace ademono
