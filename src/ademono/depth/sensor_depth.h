#pragma once
// The dataset's own depth (RGB-D sensors, synthetic sequences): FrameData::depth passed through.

#include <string>

#include "ademono/perception/depth_provider.h"

namespace ademono {

class SensorDepthProvider : public DepthProvider {
 public:
  // Throws InputError naming the dataset when `sequence` has no depth (null: checked per frame).
  explicit SensorDepthProvider(const Sequence* sequence);
  std::string Name() const override { return "sensor"; }
  // The frame's depth (CV_32FC1 metres). InputError naming the frame if it has none or if its
  // size differs from the image.
  cv::Mat Depth(const FrameData& frame, const Camera& camera) override;
  bool ReadsSequenceDepth() const override { return true; }
};

}  // namespace ademono
