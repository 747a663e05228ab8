#include "ademono/detect/yolo_detector.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "ademono/core/error.h"
#include "ademono/perception/detection_io.h"

namespace ademono {
namespace {

constexpr int kStrides[] = {8, 16, 32};
constexpr int kDynamicInputSize = 640;
constexpr double kPadValue = 114.0;

int64_t GridCells(cv::Size input_size) {
  int64_t cells = 0;
  for (int stride : kStrides) {
    cells += static_cast<int64_t>(input_size.height / stride) * (input_size.width / stride);
  }
  return cells;
}

std::string ClassName(int class_id) {
  const auto& names = CocoClassNames();
  if (class_id >= 0 && class_id < static_cast<int>(names.size())) return names[class_id];
  return "class" + std::to_string(class_id);
}

// Checks a 1xAxB output and returns {A, B}.
std::pair<int64_t, int64_t> RowsCols(const Tensor& output, const char* layout) {
  if (output.shape.size() != 3 || output.shape[0] != 1) {
    throw std::invalid_argument(std::string("expected a 1xNxK output for ") + layout + ", got " +
                                ShapeToString(output.shape));
  }
  if (output.shape[1] < 0 || output.shape[2] < 0 ||
      static_cast<size_t>(output.shape[1] * output.shape[2]) != output.data.size()) {
    throw std::invalid_argument(std::string(layout) + " output " + ShapeToString(output.shape) +
                                " does not match its " + std::to_string(output.data.size()) +
                                " values");
  }
  return {output.shape[1], output.shape[2]};
}

Detection MakeCandidate(int class_id, float score, float cx, float cy, float w, float h) {
  Detection d;
  d.class_id = class_id;
  d.class_name = ClassName(class_id);
  d.score = score;
  d.box = cv::Rect2f(cx - 0.5f * w, cy - 0.5f * h, w, h);
  return d;
}

float Iou(const cv::Rect2f& a, const cv::Rect2f& b) {
  const float inter = (a & b).area();
  const float uni = a.area() + b.area() - inter;
  return uni > 0.f ? inter / uni : 0.f;
}

}  // namespace

YoloArch ParseYoloArch(const std::string& name) {
  if (name == "auto") return YoloArch::kAuto;
  if (name == "yolox") return YoloArch::kYolox;
  if (name == "yolov5") return YoloArch::kYolov5;
  if (name == "yolov8") return YoloArch::kYolov8;
  throw std::invalid_argument("unknown detector arch '" + name +
                              "' (expected yolox, yolov5 or yolov8)");
}

std::string YoloArchName(YoloArch arch) {
  switch (arch) {
    case YoloArch::kYolox:
      return "yolox";
    case YoloArch::kYolov5:
      return "yolov5";
    case YoloArch::kYolov8:
      return "yolov8";
    case YoloArch::kAuto:
      break;
  }
  return "auto";
}

YoloArch GuessYoloArch(const std::vector<int64_t>& shape, cv::Size input_size) {
  if (shape.size() != 3 || shape[0] != 1 || shape[1] <= 0 || shape[2] <= 0) return YoloArch::kAuto;
  const int64_t cells = GridCells(input_size);
  if (shape[1] >= 5 && shape[2] == cells) return YoloArch::kYolov8;
  if (shape[2] >= 6 && shape[1] == cells) return YoloArch::kYolox;
  if (shape[2] >= 6 && shape[1] == 3 * cells) return YoloArch::kYolov5;
  return YoloArch::kAuto;
}

std::vector<Detection> DecodeYolox(const Tensor& output, cv::Size input_size,
                                   float score_threshold) {
  const auto [rows, cols] = RowsCols(output, "yolox");
  if (cols < 6) throw std::invalid_argument("yolox output needs >= 6 values per anchor");
  if (rows != GridCells(input_size)) {
    throw std::invalid_argument("yolox output has " + std::to_string(rows) +
                                " anchors, strides 8/16/32 on " + std::to_string(input_size.width) +
                                "x" + std::to_string(input_size.height) + " give " +
                                std::to_string(GridCells(input_size)));
  }
  const int num_classes = static_cast<int>(cols - 5);
  std::vector<Detection> candidates;
  int64_t row = 0;
  for (int stride : kStrides) {
    const int grid_w = input_size.width / stride;
    const int grid_h = input_size.height / stride;
    for (int gy = 0; gy < grid_h; ++gy) {
      for (int gx = 0; gx < grid_w; ++gx, ++row) {
        const float* v = output.data.data() + row * cols;
        const float* cls = v + 5;
        const int best = static_cast<int>(std::max_element(cls, cls + num_classes) - cls);
        const float score = v[4] * cls[best];
        if (score < score_threshold) continue;
        candidates.push_back(MakeCandidate(best, score, (v[0] + gx) * stride, (v[1] + gy) * stride,
                                           std::exp(v[2]) * stride, std::exp(v[3]) * stride));
      }
    }
  }
  return candidates;
}

std::vector<Detection> DecodeYolov5(const Tensor& output, float score_threshold) {
  const auto [rows, cols] = RowsCols(output, "yolov5");
  if (cols < 6) throw std::invalid_argument("yolov5 output needs >= 6 values per anchor");
  const int num_classes = static_cast<int>(cols - 5);
  std::vector<Detection> candidates;
  for (int64_t row = 0; row < rows; ++row) {
    const float* v = output.data.data() + row * cols;
    if (v[4] < score_threshold) continue;  // obj * cls <= obj
    const float* cls = v + 5;
    const int best = static_cast<int>(std::max_element(cls, cls + num_classes) - cls);
    const float score = v[4] * cls[best];
    if (score < score_threshold) continue;
    candidates.push_back(MakeCandidate(best, score, v[0], v[1], v[2], v[3]));
  }
  return candidates;
}

std::vector<Detection> DecodeYolov8(const Tensor& output, float score_threshold) {
  const auto [channels, anchors] = RowsCols(output, "yolov8");
  if (channels < 5) throw std::invalid_argument("yolov8 output needs >= 5 channels");
  const int num_classes = static_cast<int>(channels - 4);
  const float* data = output.data.data();
  std::vector<Detection> candidates;
  for (int64_t a = 0; a < anchors; ++a) {
    int best = 0;
    float best_score = data[4 * anchors + a];
    for (int c = 1; c < num_classes; ++c) {
      const float s = data[(4 + c) * anchors + a];
      if (s > best_score) best_score = s, best = c;
    }
    if (best_score < score_threshold) continue;
    candidates.push_back(MakeCandidate(best, best_score, data[a], data[anchors + a],
                                       data[2 * anchors + a], data[3 * anchors + a]));
  }
  return candidates;
}

std::vector<Detection> Nms(std::vector<Detection> candidates, float iou_threshold,
                           bool class_agnostic) {
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Detection& a, const Detection& b) { return a.score > b.score; });
  std::vector<Detection> kept;
  for (auto& candidate : candidates) {
    bool suppressed = false;
    for (const auto& k : kept) {
      if ((class_agnostic || k.class_id == candidate.class_id) &&
          Iou(k.box, candidate.box) > iou_threshold) {
        suppressed = true;
        break;
      }
    }
    if (!suppressed) kept.push_back(std::move(candidate));
  }
  return kept;
}

YoloDetector::YoloDetector(const std::filesystem::path& model_path, YoloArch arch,
                           const DetectorOptions& options)
    : arch_(arch), options_(options) {
  options_.Check();
  OrtSessionOptions session_options;
  session_options.intra_op_threads = options.num_threads;
  session_ = std::make_unique<OrtSession>(model_path, session_options);
  const auto& in = session_->Inputs()[0].shape;
  if (in.size() != 4 || (in[1] != 3 && in[1] != -1)) {
    ThrowInputError(model_path,
                    "detector input must be 1x3xHxW, the model has " + ShapeToString(in));
  }
  input_size_ = {in[3] > 0 ? static_cast<int>(in[3]) : kDynamicInputSize,
                 in[2] > 0 ? static_cast<int>(in[2]) : kDynamicInputSize};
  const auto& out = session_->Outputs()[0].shape;
  if (out.size() != 3) {
    ThrowInputError(model_path,
                    "detector output must be 1xNxK (yolox/yolov5) or 1xKxN (yolov8), "
                    "the model has " +
                        ShapeToString(out));
  }
  if (arch_ == YoloArch::kAuto) {
    arch_ = GuessYoloArch(out, input_size_);
    if (arch_ == YoloArch::kAuto) {
      ThrowInputError(model_path, "cannot tell the YOLO layout of output " + ShapeToString(out) +
                                      " for input " + ShapeToString(in) +
                                      "; add ,arch=yolox|yolov5|yolov8");
    }
  }
  const bool transposed = arch_ == YoloArch::kYolov8;
  const int64_t values = transposed ? out[1] : out[2];
  const int64_t min_values = transposed ? 5 : 6;
  if (values > 0 && values < min_values) {
    ThrowInputError(model_path, YoloArchName(arch_) +
                                    " output needs >= " + std::to_string(min_values) +
                                    " values per box, the model has " + ShapeToString(out));
  }
  if (arch_ == YoloArch::kYolox && out[1] > 0 && out[1] != GridCells(input_size_)) {
    ThrowInputError(model_path, "yolox output " + ShapeToString(out) + " does not match the " +
                                    std::to_string(GridCells(input_size_)) +
                                    " grid cells of input " + ShapeToString(in));
  }
}

std::string YoloDetector::Name() const {
  return "model:" + session_->Path().string() + ",arch=" + YoloArchName(arch_);
}

std::vector<Detection> YoloDetector::Detect(const FrameData& frame) {
  return DetectImage(frame.image);
}

std::vector<Detection> YoloDetector::DetectImage(const cv::Mat& image) const {
  if (image.empty()) throw std::invalid_argument("YoloDetector: empty image");
  const bool yolox = arch_ == YoloArch::kYolox;
  ResizeTransform transform;
  const cv::Size content = FitInside(image.size(), input_size_, /*round_content=*/!yolox);
  const cv::Mat input = ResizeAndPad(image, content, input_size_,
                                     yolox ? PadPlacement::kTopLeft : PadPlacement::kCentre,
                                     cv::Scalar::all(kPadValue), cv::INTER_LINEAR, &transform);
  const std::vector<float> blob =
      yolox ? ImageToBlob(input, /*to_rgb=*/false, {0, 0, 0}, {1, 1, 1})
            : ImageToBlob(input, /*to_rgb=*/true, {0, 0, 0}, {255, 255, 255});
  const auto outputs = session_->Run(blob, {1, 3, input_size_.height, input_size_.width});
  std::vector<Detection> candidates;
  try {
    switch (arch_) {
      case YoloArch::kYolox:
        candidates = DecodeYolox(outputs[0], input_size_, options_.score_threshold);
        break;
      case YoloArch::kYolov5:
        candidates = DecodeYolov5(outputs[0], options_.score_threshold);
        break;
      default:
        candidates = DecodeYolov8(outputs[0], options_.score_threshold);
        break;
    }
  } catch (const std::invalid_argument& e) {
    ThrowInputError(session_->Path(), e.what());
  }
  if (!options_.class_ids.empty()) {
    std::erase_if(candidates, [&](const Detection& d) {
      return std::find(options_.class_ids.begin(), options_.class_ids.end(), d.class_id) ==
             options_.class_ids.end();
    });
  }
  std::vector<Detection> detections =
      Nms(std::move(candidates), options_.nms_iou, options_.class_agnostic_nms);
  const cv::Rect2f bounds(0.f, 0.f, static_cast<float>(image.cols), static_cast<float>(image.rows));
  for (auto& d : detections) {
    const cv::Point2d tl = transform.ToOriginal({d.box.x, d.box.y});
    const cv::Point2d br = transform.ToOriginal({d.box.x + d.box.width, d.box.y + d.box.height});
    d.box = cv::Rect2f(cv::Point2f(tl), cv::Point2f(br)) & bounds;
  }
  std::erase_if(detections, [](const Detection& d) { return d.box.area() <= 0.f; });
  return detections;
}

}  // namespace ademono
