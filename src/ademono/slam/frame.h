#pragma once
// A tracked frame: its kept ORB features (after the filters) with per-keypoint metric depth, the
// virtual right coordinate of the RGB-D mode and a grid for window searches; plus the tracking
// state (pose, map point matches, outliers).

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ademono/core/camera.h"
#include "ademono/core/depth_error.h"
#include "ademono/core/geometry.h"
#include "ademono/optimize/optimizer_types.h"

namespace ademono {

class MapPoint;
class KeyFrame;

// Scale pyramid of the ORB extractor.
struct ScalePyramid {
  int num_levels = 1;
  float log_scale_factor = 0.f;
  std::vector<float> scale_factors, inv_scale_factors, level_sigma2, inv_level_sigma2;
  static ScalePyramid Make(int num_levels, float scale_factor);
};

// Immutable feature data shared by a frame and the keyframe made from it.
struct FrameFeatures {
  static constexpr int kGridCols = 64;
  static constexpr int kGridRows = 48;

  Camera camera;
  std::shared_ptr<const ScalePyramid> pyramid;
  PinholeIntrinsics intrinsics;                      // fx, fy, cx, cy, bf
  float close_depth = 0.f;                           // ThDepth in metres
  float min_x = 0, max_x = 0, min_y = 0, max_y = 0;  // undistorted image bounds
  std::vector<cv::KeyPoint> keypoints;               // as extracted (distorted pixels)
  std::vector<cv::KeyPoint> keypoints_un;            // undistorted
  cv::Mat descriptors;                               // CV_8UC1, 32 bytes per row
  std::vector<float> depth;                          // metres, <= 0 when unknown
  std::vector<float> u_right;                        // u - bf / depth, < 0 when unknown
  // Error model of `depth` (disabled for sensor depth); scaled with the depths it describes.
  DepthErrorModel depth_error;
  bool weight_by_error_model = true;  // false: the virtual baseline's weighting (ablation)
  // Monocular (tracking.monocular): the depths are no measurement. No u_right (2-dof residuals,
  // no depth check in matching); the depths only seed the first map, measure the scale and give
  // the priors of points geometry cannot place (PriorObservation).
  bool monocular = false;
  float depth_scale = 1.f;  // factor applied to the source's depths (network scale correction)
  // The keypoints by grid cell (kGridCols x kGridRows, row-major), for window searches: cell c's
  // are grid_entries[grid_begin[c], grid_begin[c + 1]), in index order. Flat and packed because
  // tracking scans it for every projected map point (a vector per cell was 11 % of a monocular
  // run's tracking thread, nearly all of it cache misses). Empty without keypoints.
  struct GridEntry {
    float x, y;  // undistorted position
    int octave;
    uint32_t index;
  };
  std::vector<uint32_t> grid_begin;
  std::vector<GridEntry> grid_entries;

  size_t Size() const { return keypoints.size(); }
  // Keypoints whose undistorted position lies within the square window of radius r, on pyramid
  // levels [min_level, max_level] (negative = unbounded). Ascending index order.
  std::vector<size_t> FeaturesInArea(float u, float v, float r, int min_level = -1,
                                     int max_level = -1) const;
  // The same into `out` (cleared first), whose capacity a caller's loop reuses.
  void FeaturesInArea(float u, float v, float r, int min_level, int max_level,
                      std::vector<size_t>* out) const;
  bool InBounds(float u, float v) const {
    return u >= min_x && u < max_x && v >= min_y && v < max_y;
  }
  ImageObservation Observation(size_t i) const;
  // Keypoint i with a depth prior `z` of standard deviation `sigma_z` as a 3-dof
  // (u, v, u_right) observation, also in monocular mode (a network depth prior); z > 0.
  ImageObservation PriorObservation(size_t i, double z, double sigma_z) const;
  // Camera-frame point of keypoint i from its depth (requires depth[i] > 0).
  Eigen::Vector3d UnprojectCamera(size_t i) const;
  bool IsClose(size_t i) const { return depth[i] > 0 && depth[i] < close_depth; }
  // Whether depth is a prior with an error model (network) rather than a sensor reading.
  bool DepthIsPrior() const { return depth_error.Enabled(); }
};

// Builds the features: undistorts keypoints, computes u_right and assigns the grid.
std::shared_ptr<const FrameFeatures> MakeFrameFeatures(const Camera& camera,
                                                       std::shared_ptr<const ScalePyramid> pyramid,
                                                       double virtual_baseline, double close_depth,
                                                       std::vector<cv::KeyPoint> keypoints,
                                                       cv::Mat descriptors,
                                                       std::vector<float> depth,
                                                       const DepthErrorModel& depth_error = {},
                                                       bool weight_by_error_model = true,
                                                       bool monocular = false);

// The features without any keypoint (camera, pyramid, bounds and depth model kept): what a culled
// keyframe needs, whose pose still resolves the frames that referenced it.
std::shared_ptr<const FrameFeatures> WithoutKeypoints(const FrameFeatures& features);

// The same features with no depth (every depth and u_right unknown): a depth sensor's frame
// tracked against a map in other units (BackEnd::Track).
std::shared_ptr<const FrameFeatures> WithoutDepth(const FrameFeatures& features);

// The same features with every depth multiplied by `scale` (u_right recomputed, depth_scale
// accumulated): the per-frame scale correction of network depth.
std::shared_ptr<const FrameFeatures> RescaleDepth(const FrameFeatures& features, float scale);

// Where a map point is expected in a frame (filled by Frame::InFrustum for the local-map search).
struct ProjectionPrediction {
  float u = 0, v = 0, u_right = -1;
  int level = 0;
  float view_cos = 1;
};

class Frame {
 public:
  Frame(uint64_t id, size_t index, double timestamp, std::shared_ptr<const FrameFeatures> features);

  uint64_t id;
  size_t index;  // input sequence index
  double timestamp;
  std::shared_ptr<const FrameFeatures> features;
  std::vector<std::shared_ptr<MapPoint>> map_points;  // matched map point per keypoint
  std::vector<bool> outlier;
  std::optional<Rigid3d> cam_from_world;
  KeyFrame* reference_keyframe = nullptr;

  const FrameFeatures& F() const { return *features; }
  Eigen::Vector3d CameraCenter() const { return cam_from_world->inverse().translation(); }
  // Whether `point` can be seen by this frame (in front, inside the image, within its scale
  // range and viewing angle); fills `prediction` when it can.
  bool InFrustum(const MapPoint& point, float view_cos_limit,
                 ProjectionPrediction* prediction) const;
  int NumTrackedInliers() const;
};

}  // namespace ademono
