#include "ademono/depth/sensor_depth.h"

#include <cmath>

#include "ademono/core/error.h"

namespace ademono {

SensorDepthProvider::SensorDepthProvider(const Sequence* sequence) {
  if (sequence != nullptr && !sequence->HasDepth()) {
    ThrowInputError(sequence->Path(), "dataset '" + sequence->Kind() +
                                          "' has no sensor depth; use --depth cache:DIR or "
                                          "model:FILE.onnx");
  }
}

cv::Mat SensorDepthProvider::Depth(const FrameData& frame, const Camera& /*camera*/) {
  if (frame.depth.empty()) {
    ThrowInputError(frame.name, "frame " + std::to_string(frame.index) + " has no sensor depth");
  }
  if (frame.depth.type() != CV_32FC1) {
    ThrowInputError(frame.name, "sensor depth is not CV_32FC1 metres");
  }
  if (!frame.image.empty() && frame.depth.size() != frame.image.size()) {
    ThrowInputError(frame.name, "sensor depth size " + std::to_string(frame.depth.cols) + "x" +
                                    std::to_string(frame.depth.rows) +
                                    " differs from the image size");
  }
  // Non-finite values are invalid depth; normalise them to 0 as the contract asks.
  cv::Mat depth = frame.depth.clone();
  depth.forEach<float>([](float& z, const int*) {
    if (!std::isfinite(z) || z < 0.f) z = 0.f;
  });
  return depth;
}

}  // namespace ademono
