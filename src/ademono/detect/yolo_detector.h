#pragma once
// YOLO-family object detectors exported to ONNX, run through ONNX Runtime.
//
// Model contracts (input 1x3xHxW float, H and W fixed or dynamic -> 640):
// - yolox:  BGR 0..255, no normalisation, letterbox at the top-left, pad 114. Output 1xNx(5+C)
//           raw head: (x, y) offsets in grid cells, (w, h) log-sizes, objectness and class
//           probabilities (sigmoid applied); N = sum over strides 8, 16, 32 of (H/s)*(W/s).
//           Box centre = (xy + grid) * stride, size = exp(wh) * stride, score = obj * cls.
// - yolov5: RGB / 255, letterbox centred, pad 114. Output 1xNx(5+C): centre x, y, w, h in input
//           pixels, objectness, class probabilities; score = obj * cls.
// - yolov8: as yolov5 for the input. Output 1x(4+C)xN (transposed): centre x, y, w, h, class
//           scores; no objectness.
// Each anchor keeps its best class; candidates above the score threshold go through class-aware
// NMS (boxes of different classes never suppress each other; optionally class-agnostic), then
// the class filter.
// Boxes are returned in original-image pixels, clipped to the image, sorted by score.

#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "ademono/detect/detector_factory.h"
#include "ademono/dnn/ort_session.h"
#include "ademono/dnn/preprocess.h"
#include "ademono/perception/detection.h"

namespace ademono {

enum class YoloArch { kAuto, kYolox, kYolov5, kYolov8 };

// "auto", "yolox", "yolov5", "yolov8"; throws std::invalid_argument otherwise.
YoloArch ParseYoloArch(const std::string& name);
std::string YoloArchName(YoloArch arch);

// Picks the architecture from the output shape for a network input of `input_size`:
// with `cells` the grid cells of strides 8/16/32: 1x(4+C)xcells -> yolov8, 1xcellsx(5+C) -> yolox,
// 1x(3*cells)x(5+C) -> yolov5 (three anchors per cell). Returns kAuto when the shape fits none.
YoloArch GuessYoloArch(const std::vector<int64_t>& output_shape, cv::Size input_size);

// Decoders: candidates (best class per anchor, score >= threshold) with boxes in network-input
// pixels. Throw std::invalid_argument for an output whose shape does not fit the layout.
std::vector<Detection> DecodeYolox(const Tensor& output, cv::Size input_size,
                                   float score_threshold);
std::vector<Detection> DecodeYolov5(const Tensor& output, float score_threshold);
std::vector<Detection> DecodeYolov8(const Tensor& output, float score_threshold);

// Greedy NMS: a box is dropped when its IoU with a higher-scoring kept box of the same class
// (any class when `class_agnostic`) exceeds `iou_threshold`. Stable: ties keep the earlier
// candidate. Sorted by score.
std::vector<Detection> Nms(std::vector<Detection> candidates, float iou_threshold,
                           bool class_agnostic = false);

class YoloDetector : public Detector {
 public:
  // Throws InputError naming the file for a missing/corrupt model or an output shape that does
  // not fit `arch` (kAuto: guessed from the shape).
  YoloDetector(const std::filesystem::path& model_path, YoloArch arch,
               const DetectorOptions& options);
  std::string Name() const override;
  std::vector<Detection> Detect(const FrameData& frame) override;
  // Same on a bare BGR (or grey) image.
  std::vector<Detection> DetectImage(const cv::Mat& image) const;

  YoloArch Arch() const { return arch_; }
  cv::Size InputSize() const { return input_size_; }
  const OrtSession& Session() const { return *session_; }

 private:
  std::unique_ptr<OrtSession> session_;
  YoloArch arch_;
  DetectorOptions options_;
  cv::Size input_size_;
};

}  // namespace ademono
