#pragma once
// Where per-frame metric depth comes from. SLAM asks a DepthProvider for each frame; providers
// are the dataset's sensor depth, cached depth maps, a simulated network (synth) or an ONNX model.

#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "ademono/core/camera.h"
#include "ademono/io/sequence.h"

namespace ademono {

class DepthProvider {
 public:
  virtual ~DepthProvider() = default;
  virtual std::string Name() const = 0;
  // CV_32FC1 depth in metres at the image's resolution, 0 where invalid.
  // Must be deterministic for the same frame (and seed) and safe to call from a worker thread.
  virtual cv::Mat Depth(const FrameData& frame, const Camera& camera) = 0;
  // Whether Depth reads FrameData::depth (the dataset's own depth images); when not, the
  // pipeline loads frames without decoding them (Sequence::LoadWithoutDepth).
  virtual bool ReadsSequenceDepth() const { return false; }
};

// Whether frames must be loaded with their depth images for `depth` (none: no provider).
inline bool ReadsSequenceDepth(const DepthProvider* depth) {
  return depth != nullptr && depth->ReadsSequenceDepth();
}

}  // namespace ademono
