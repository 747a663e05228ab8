#pragma once
// Image -> network-input helpers shared by the depth and detector models: keep-aspect resize
// with padding (letterbox) and HWC uint8 -> NCHW float conversion with normalisation.

#include <array>
#include <opencv2/core.hpp>
#include <vector>

namespace ademono {

enum class PadPlacement {
  kTopLeft,  // content at the top-left, padding right and bottom (YOLOX)
  kCentre,   // content centred, padding split on both sides (YOLOv5/v8, Metric3D)
};

// Where the original image landed inside the network input: original pixel (u, v) maps to
// (u * scale_x + offset.x, v * scale_y + offset.y), covering `content` (in input pixels).
struct ResizeTransform {
  double scale_x = 1.0;
  double scale_y = 1.0;
  cv::Point2d offset{0, 0};
  cv::Rect content;
  cv::Size input_size;

  cv::Point2d ToOriginal(const cv::Point2d& input_px) const {
    return {(input_px.x - offset.x) / scale_x, (input_px.y - offset.y) / scale_y};
  }
};

// Scales `image` uniformly into `content_size` (computed by the caller), then pads it to
// `input_size` with `pad_value`. `content_size` must fit inside `input_size`.
cv::Mat ResizeAndPad(const cv::Mat& image, cv::Size content_size, cv::Size input_size,
                     PadPlacement placement, const cv::Scalar& pad_value, int interpolation,
                     ResizeTransform* transform);

// Largest uniform scale that fits `image_size` inside `input_size`; `round_content` rounds the
// scaled size (Ultralytics) instead of truncating it (YOLOX).
cv::Size FitInside(cv::Size image_size, cv::Size input_size, bool round_content);

// HWC uint8 (3 channels, BGR as OpenCV stores it) -> NCHW float:
//   out[c] = (pixel[c] - mean[c]) / std[c], with pixel, mean and std in 0..255 units and
// channels in RGB order when `to_rgb`, BGR otherwise (mean/std are in the output order).
std::vector<float> ImageToBlob(const cv::Mat& image, bool to_rgb, const std::array<double, 3>& mean,
                               const std::array<double, 3>& std);

}  // namespace ademono
