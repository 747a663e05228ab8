#pragma once
// The front end of the SLAM system (stella_vslam / Kimera style): everything done to one input
// frame before it meets the map.
//   Extract:  grey image, ORB extraction, each keypoint's depth. Pure per frame (no state), so a
//             runner may extract frame k+1 on another thread while frame k is in the back end.
//   Filter:   the method's filters (enhancement, dynamic removal, distant), the kept subset and
//             its frame features, and the detections the filter found moving. Needs the back
//             end's prediction for this frame and what Remember() kept of the previous frame, so
//             it runs in frame order.
//   Remember: what the dynamic filter needs of this frame next time (after the back end).

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "ademono/core/camera.h"
#include "ademono/feature/orb_extractor.h"
#include "ademono/filter/feature_filter.h"
#include "ademono/io/sequence.h"
#include "ademono/perception/detection.h"
#include "ademono/slam/frame.h"
#include "ademono/slam/options.h"

namespace ademono {

// One frame after extraction: all keypoints, their descriptors and depths (<= 0: none).
struct ExtractedFrame {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  std::vector<float> depths;
  double extraction_ms = 0;  // grey conversion + ORB
  double depth_ms = 0;       // keypoint depth look-up
};

// One frame ready for the back end.
struct FilteredFrame {
  std::vector<PointLabel> labels;  // one per extracted keypoint
  FilterStats filter_stats;
  int num_kept = 0;
  int num_with_depth = 0;
  std::shared_ptr<const FrameFeatures> features;  // the kept keypoints only
  // Detections that hold a moving object by the filter's vote (dynamic map-point culling).
  std::vector<Detection> moving_detections;
  // Per kept keypoint: 1 inside a grown dynamic-class box (the geometric test's box prior);
  // empty when the frame has no such box or the test is off.
  std::vector<uint8_t> in_dynamic_box;
  double filter_ms = 0;    // filters and the kept subset
  double features_ms = 0;  // frame features and the moving-box vote
};

class FrontEnd {
 public:
  FrontEnd(const Camera& camera, const SystemOptions& options);

  // `depth`: CV_32FC1 metres at the image's size or empty; `image` CV_8UC1 or CV_8UC3.
  // Thread-safe (const, no state): may run concurrently with Filter/Remember of another frame.
  // Extract = ExtractFeatures + AddDepths; the two halves let a runner extract while the frame's
  // depth is still being computed.
  ExtractedFrame Extract(const FrameData& frame, const cv::Mat& depth) const;
  ExtractedFrame ExtractFeatures(const FrameData& frame) const;  // no depths yet
  void AddDepths(ExtractedFrame& extracted, const cv::Mat& depth) const;
  FilteredFrame Filter(const ExtractedFrame& extracted, const std::vector<Detection>& detections,
                       const std::optional<Rigid3d>& predicted_cam_from_world);
  // After the back end: this frame's keypoints as the previous frame of the next Filter call.
  void Remember(const ExtractedFrame& extracted, const std::optional<Rigid3d>& cam_from_world);

  // Per-keypoint depth from the depth map: nearest pixel, range and discontinuity checks.
  static std::vector<float> KeypointDepths(const std::vector<cv::KeyPoint>& keypoints,
                                           const cv::Mat& depth, const FrameDepthOptions& options);

  // The scale pyramid of every frame's keypoints (restored keyframes of a loaded map share it).
  const std::shared_ptr<const ScalePyramid>& Pyramid() const { return pyramid_; }

 private:
  Camera camera_;
  SystemOptions options_;
  OrbExtractor extractor_;
  std::shared_ptr<const ScalePyramid> pyramid_;
  FeatureFilter filter_;
  std::optional<PreviousFrameFeatures> previous_;
};

}  // namespace ademono
