#include "ademono/slam/system.h"

#include <algorithm>
#include <stdexcept>

namespace ademono {

System::System(const Camera& camera, const SystemOptions& options)
    : camera_(camera), options_(options), front_end_(camera, options), back_end_(camera, options) {
  camera_.Check();
  options_.Check();
}

System::~System() { Shutdown(); }

void System::Shutdown() { back_end_.Shutdown(); }

namespace {

void CheckDepth(const FrameData& frame, const cv::Mat& depth) {
  if (!depth.empty() && (depth.type() != CV_32FC1 || depth.size() != frame.image.size())) {
    throw std::invalid_argument("System::TrackFrame: depth must be CV_32FC1 at the image size");
  }
}

}  // namespace

TrackResult System::TrackFrame(const FrameData& frame, const cv::Mat& depth,
                               const std::vector<Detection>& detections) {
  CheckDepth(frame, depth);
  return TrackFrame(frame, depth, detections, front_end_.Extract(frame, depth));
}

TrackResult System::TrackFrame(const FrameData& frame, const cv::Mat& depth,
                               const std::vector<Detection>& detections,
                               ExtractedFrame extracted) {
  TrackResult result;
  result.index = frame.index;
  CheckDepth(frame, depth);
  if (extracted.depths.size() != extracted.keypoints.size()) {
    throw std::invalid_argument("System::TrackFrame: extracted frame without keypoint depths");
  }
  back_end_.HandOff();
  const FilteredFrame filtered =
      front_end_.Filter(extracted, detections, back_end_.PredictNext());
  const BackEndResult back = back_end_.Track(frame, depth, filtered);
  const TrackingOutput& out = back.tracking;
  front_end_.Remember(extracted, out.tracked ? std::optional<Rigid3d>(out.cam_from_world)
                                             : std::nullopt);

  result.num_keypoints = static_cast<int>(extracted.keypoints.size());
  result.num_kept = filtered.num_kept;
  result.num_with_depth = filtered.num_with_depth;
  result.filter_stats = filtered.filter_stats;
  result.extraction_ms = extracted.extraction_ms;
  result.keypoint_depth_ms = extracted.depth_ms;
  result.filter_ms = filtered.filter_ms;
  result.tracking_ms = filtered.features_ms + back.tracking_ms;
  result.mapping_ms = back.mapping_ms;
  result.state = back.state;
  result.tracked = out.tracked;
  result.inliers = out.inliers;
  result.relocalised = out.relocalised;
  result.dynamic_points_culled = out.dynamic_points_culled;
  result.quality = out.quality;
  result.geometric_dynamic = out.geometric_dynamic;
  result.geometric_culled = out.geometric_culled;
  // Back from the kept keypoints (the features) to all extracted keypoints.
  std::vector<size_t> extracted_index;  // feature index -> extracted keypoint index
  if (!out.match_state.empty() || !out.created_points.empty()) {
    for (size_t i = 0; i < extracted.keypoints.size(); ++i) {
      if (FeedsTracking(filtered.labels[i], options_.filter)) extracted_index.push_back(i);
    }
  }
  if (!out.match_state.empty()) {
    result.match_state.assign(extracted.keypoints.size(), MatchState::kUnmatched);
    for (size_t k = 0; k < std::min(extracted_index.size(), out.match_state.size()); ++k)
      result.match_state[extracted_index[k]] = out.match_state[k];
  }
  for (const auto& [k, point] : out.created_points) {
    if (k < extracted_index.size()) result.created_points.emplace_back(extracted_index[k], point);
  }
  result.depth_scale = out.depth_scale;
  result.scale_sigma = out.scale_sigma;
  if (out.tracked) result.cam_from_world = out.cam_from_world;
  result.new_keyframe = back.new_keyframe;
  result.keypoints = std::move(extracted.keypoints);
  result.labels = filtered.labels;
  return result;
}

Trajectory System::FrameTrajectory(FramePoses poses, PoseSmoothingReport* smoothing) const {
  return back_end_.FrameTrajectory(poses, smoothing);
}
Trajectory System::KeyFrameTrajectory() const { return back_end_.KeyFrameTrajectory(); }
std::vector<std::pair<size_t, double>> System::DepthScales() const {
  return back_end_.DepthScales();
}
std::vector<System::ColoredPoint> System::MapPointCloud() const {
  return back_end_.MapPointCloud();
}
size_t System::NumKeyFrames() const { return back_end_.NumKeyFrames(); }
size_t System::NumMapPoints() const { return back_end_.NumMapPoints(); }
int System::NumLost() const { return back_end_.NumLost(); }
std::vector<double> System::GroundHeights() const { return back_end_.GroundHeights(); }
int System::NumTracked() const { return back_end_.NumTracked(); }

}  // namespace ademono
