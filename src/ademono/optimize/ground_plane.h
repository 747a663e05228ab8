#pragma once
// The ground plane under a forward-looking camera, from 3D points in the camera frame (x right,
// y down, z forward), and the camera's height above it. A vehicle's camera height is known
// (KITTI: 1.65 m), so the ratio of the configured to the measured height is the scale error of a
// network's depth: the usual remedy for monocular driving odometry, here applied to a metric
// network's bias (slam/tracking.h, depth.camera_height).
//
// RANSAC over planes through three points whose normal lies within max_tilt_deg of the camera's
// up axis (-y), inliers within inlier_ratio * height of the plane; the best plane is refitted by
// maximum likelihood for depth errors proportional to depth (ground_plane.cpp). A raised surface
// as populous as the road beside it (a sidewalk 15 cm up) draws a plane through both: callers
// pass a corridor ahead. Deterministic: a fixed-seed std::mt19937, taken modulo (the engine's
// sequence is fixed by the standard, unlike the distributions).

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <vector>

#include "ademono/core/camera.h"
#include "ademono/core/geometry.h"

namespace ademono {

struct GroundPlaneOptions {
  double max_tilt_deg = 15.0;     // the plane's normal within this angle of the camera's up axis
  double inlier_ratio = 0.05;     // inlier distance as a fraction of the candidate's height
  int min_inliers = 50;           // fewer: no estimate
  double min_inlier_share = 0.2;  // of the points given
  int iterations = 300;
  void Check() const;  // throws std::invalid_argument
};

struct GroundPlane {
  bool valid = false;
  Eigen::Vector3d normal =
      Eigen::Vector3d(0, -1, 0);  // unit, pointing from the plane to the camera
  double height = 0.0;            // camera's distance above the plane, in the points' units
  int num_inliers = 0;
  int num_points = 0;             // points given (the candidates)
  std::vector<int> inliers;       // indices into the points given of those on the plane
  // How much to trust it (valid estimates only): the share of the candidates on the plane, the
  // robust spread (1.4826 MAD) of the inliers' log-depth residuals, the height's standard error
  // relative to the height from the refit's covariance at that spread (an optimistic bound:
  // a network's errors are correlated across the frame), and one number in [0, 1] from them,
  // inlier_share * exp(-height_sigma / 0.01): a road that fills the corridor and pins the
  // height within 1 % gives about 0.3 or more; a car ahead or a kerb in the corridor less.
  double inlier_share = 0.0;
  double residual_sigma = 0.0;
  double height_sigma = 0.0;
  double confidence = 0.0;
};

// `points_cam`: candidate ground points in the camera frame (callers pass those below the
// horizon and off dynamic objects). Points on other surfaces are outliers.
GroundPlane EstimateGroundPlane(const std::vector<Eigen::Vector3d>& points_cam,
                                const GroundPlaneOptions& options = {});

// The road ahead of a driving camera from one frame's depth (docs/kitti.md has the measurements
// on real KITTI frames behind each default).
struct GroundFromDepthOptions {
  // The corridor fitted, in the camera frame (m, the depth's units): the lane ahead. Wider takes
  // in parked cars and kerbs; farther, the network's far depth (it reads the far road longer
  // than the near, which tilts the plane).
  double min_depth = 3.0;
  double max_depth = 20.0;
  double max_lateral = 2.0;
  // Dense maps: one pixel every `stride` in both directions.
  int stride = 4;
  // Boxes (pixels) whose pixels or keypoints are no road: detected vehicles and people, parked
  // or not.
  GroundPlaneOptions plane;
  void Check() const;  // throws std::invalid_argument
};

// Candidate road points of a dense depth map (CV_32FC1, 0 = invalid, at the camera's size):
// every `stride`-th pixel below the principal point whose point lies in the corridor and
// outside `exclude`. Distortion is undone when the camera has any.
std::vector<Eigen::Vector3d> RoadCandidates(const cv::Mat& depth, const Camera& camera,
                                            const std::vector<cv::Rect2d>& exclude,
                                            const GroundFromDepthOptions& options);
// The same selection for keypoints (pixels, distorted as observed) with depths (<= 0: none).
std::vector<Eigen::Vector3d> RoadCandidates(const std::vector<cv::Point2f>& keypoints,
                                            const std::vector<float>& depths,
                                            const Camera& camera,
                                            const std::vector<cv::Rect2d>& exclude,
                                            const GroundFromDepthOptions& options);
// The height above a plane of known normal (unit after normalising; pointing from the plane to
// the camera, e.g. the camera's up axis (0, -1, 0) for a level rig, or the map's road normal):
// the median of -normal.p, with the share of points within inlier_ratio (in log) of it.
GroundPlane GroundHeightAlong(const std::vector<Eigen::Vector3d>& points_cam,
                              const Eigen::Vector3d& normal,
                              const GroundPlaneOptions& options = {});
// The camera's height above the road and the road's normal (camera frame) from a frame's dense
// depth map, with a confidence. InvalidArgument for a depth map of the wrong type or size.
GroundPlane EstimateGroundFromDepth(const cv::Mat& depth, const Camera& camera,
                                    const std::vector<cv::Rect2d>& exclude = {},
                                    const GroundFromDepthOptions& options = {});

// The road from two views of it and their relative pose, without depth: the road's pixels in
// view a, mapped into view b by the homography the plane induces, K (R + t m^T) K^-1 with
// m = normal / height, must look the same. Gauss-Newton on m (and a gain and bias for
// exposure) over the corridor's pixels, coarse to fine, Huber-weighted. The height comes out in
// the units of b_from_a's translation (metres for ground-truth poses, the map's units for SLAM's):
// geometry measures the road where a network reads it with its own distortions (docs/kitti.md).
struct TwoViewGroundOptions {
  // The corridor in view a, placed with the initial plane: its depth range and half width
  // (initial plane units), off the excluded boxes.
  double min_depth = 5.0;
  double max_depth = 15.0;
  double max_lateral = 2.0;
  int coarsest_level = 2;    // pyramid levels (halvings) from coarse to finest_level
  int finest_level = 1;
  int iterations = 20;       // Gauss-Newton steps per level
  double huber = 8.0;        // intensity units (0..255)
  int min_pixels = 2000;     // corridor pixels at the finest level; fewer: no estimate
  double min_inlier_share = 0.5;  // residuals within `huber`
  double min_gradient = 1.0;      // RMS image gradient over the corridor (intensity / px)
  double max_tilt_deg = 5.0;      // of the result's normal from the initial plane's
  // false: the initial normal is kept and only the height is fitted (a normal known from
  // elsewhere, e.g. the map's road over many keyframes).
  bool fit_normal = true;
  void Check() const;             // throws std::invalid_argument
};
// `image_a`, `image_b`: the two frames (CV_8UC1 or CV_8UC3, the camera's size); `b_from_a` view
// b's pose relative to a (at least a few centimetres of translation); `initial`: a plane to
// start from (normal and height in b_from_a's units, e.g. a depth fit's scaled into them, or
// the level road at the rig's height). InvalidArgument for images of the wrong size.
GroundPlane EstimateGroundFromTwoViews(const cv::Mat& image_a, const cv::Mat& image_b,
                                       const Rigid3d& b_from_a, const Camera& camera,
                                       const GroundPlane& initial,
                                       const std::vector<cv::Rect2d>& exclude = {},
                                       const TwoViewGroundOptions& options = {});

}  // namespace ademono
