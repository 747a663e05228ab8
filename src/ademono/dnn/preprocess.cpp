#include "ademono/dnn/preprocess.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace ademono {

cv::Size FitInside(cv::Size image_size, cv::Size input_size, bool round_content) {
  if (image_size.width <= 0 || image_size.height <= 0) {
    throw std::invalid_argument("FitInside: empty image");
  }
  const double scale = std::min(static_cast<double>(input_size.width) / image_size.width,
                                static_cast<double>(input_size.height) / image_size.height);
  auto to_int = [&](double v) {
    return std::max(1, static_cast<int>(round_content ? std::lround(v) : std::floor(v)));
  };
  return {std::min(input_size.width, to_int(image_size.width * scale)),
          std::min(input_size.height, to_int(image_size.height * scale))};
}

cv::Mat ResizeAndPad(const cv::Mat& image, cv::Size content_size, cv::Size input_size,
                     PadPlacement placement, const cv::Scalar& pad_value, int interpolation,
                     ResizeTransform* transform) {
  if (image.empty()) throw std::invalid_argument("ResizeAndPad: empty image");
  if (content_size.width > input_size.width || content_size.height > input_size.height) {
    throw std::invalid_argument("ResizeAndPad: content larger than the input");
  }
  cv::Mat bgr = image;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  if (image.channels() == 4) cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
  cv::Mat resized;
  if (content_size == bgr.size()) {
    resized = bgr;
  } else {
    cv::resize(bgr, resized, content_size, 0, 0, interpolation);
  }
  int left = 0, top = 0;
  const int pad_w = input_size.width - content_size.width;
  const int pad_h = input_size.height - content_size.height;
  if (placement == PadPlacement::kCentre) {
    // Ultralytics: round(d/2 - 0.1), i.e. the odd pixel goes right/bottom.
    left = static_cast<int>(std::lround(pad_w / 2.0 - 0.1));
    top = static_cast<int>(std::lround(pad_h / 2.0 - 0.1));
  }
  cv::Mat padded;
  cv::copyMakeBorder(resized, padded, top, pad_h - top, left, pad_w - left, cv::BORDER_CONSTANT,
                     pad_value);
  if (transform != nullptr) {
    transform->scale_x = static_cast<double>(content_size.width) / image.cols;
    transform->scale_y = static_cast<double>(content_size.height) / image.rows;
    transform->offset = {static_cast<double>(left), static_cast<double>(top)};
    transform->content = cv::Rect(left, top, content_size.width, content_size.height);
    transform->input_size = input_size;
  }
  return padded;
}

std::vector<float> ImageToBlob(const cv::Mat& image, bool to_rgb, const std::array<double, 3>& mean,
                               const std::array<double, 3>& std) {
  if (image.type() != CV_8UC3) throw std::invalid_argument("ImageToBlob: expected CV_8UC3");
  const int rows = image.rows, cols = image.cols;
  const size_t plane = static_cast<size_t>(rows) * cols;
  std::vector<float> blob(3 * plane);
  for (int c = 0; c < 3; ++c) {
    if (std[c] == 0.0) throw std::invalid_argument("ImageToBlob: std is zero");
  }
  // out[c] = pixel * gain + bias, precomputed per channel.
  std::array<float, 3> gain, bias;
  for (int c = 0; c < 3; ++c) {
    gain[c] = static_cast<float>(1.0 / std[c]);
    bias[c] = static_cast<float>(-mean[c] / std[c]);
  }
  for (int r = 0; r < rows; ++r) {
    const uint8_t* row = image.ptr<uint8_t>(r);
    float* out[3];
    for (int c = 0; c < 3; ++c) out[c] = blob.data() + c * plane + static_cast<size_t>(r) * cols;
    for (int x = 0; x < cols; ++x) {
      for (int c = 0; c < 3; ++c) {
        const int source = to_rgb ? 2 - c : c;
        out[c][x] = row[3 * x + source] * gain[c] + bias[c];
      }
    }
  }
  return blob;
}

}  // namespace ademono
