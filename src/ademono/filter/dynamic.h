#pragma once
// Dynamic interference removal (filter 2). Detections of dynamic classes are grown by a margin;
// points in small boxes are dropped outright, points in large boxes go through a two-stage test:
// (1) their frame-to-frame displacement against the background's, (2) the reprojection error of
// their previous world point under the constant-velocity pose prediction. See docs/filters.md.
//
// Stage 1 by default measures displacements relative to the camera's own motion
// (`stage1_motion_compensation`): the motion from the previous to the current camera is fitted
// to the background matches (PnP + RANSAC on their previous-frame depths), and each point is
// compared with where a static point at its depth would be now. Under forward motion the raw
// image flow of static points grows with image position and inverse depth, so the paper's one
// mean background displacement judges near static objects (parked cars) moving. Without enough
// background points with depth, or with compensation off, stage 1 is the paper's raw test.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "ademono/core/camera.h"
#include "ademono/core/geometry.h"
#include "ademono/filter/dynamic_params.h"
#include "ademono/filter/feature_filter.h"
#include "ademono/perception/detection.h"

namespace ademono {

struct GrownBox {
  cv::Rect2f box;            // grown by d = box_growth * diagonal on every side, clipped
  bool small = false;        // original box area / image area < small_box_area_ratio
  int detection_index = -1;  // index into the input detections
};

// The grown boxes of detections whose class is dynamic, in detection order. Boxes that are empty
// after clipping to the image are skipped.
std::vector<GrownBox> GrowDynamicBoxes(const std::vector<Detection>& detections,
                                       cv::Size image_size, const DynamicParams& params);

// True if `p` lies in the half-open box [x, x + w) x [y, y + h).
bool InsideBox(const cv::Rect2f& box, const cv::Point2f& p);

struct DynamicInput {
  const std::vector<cv::KeyPoint>* keypoints = nullptr;
  const cv::Mat* descriptors = nullptr;  // needed for stage 1/2 when `previous` is set
  std::vector<bool> active;              // points still kept by earlier filters; empty: all
  const std::vector<Detection>* detections = nullptr;
  const PreviousFrameFeatures* previous = nullptr;
  const Camera* camera = nullptr;  // image size; projection for stage 2
  std::optional<Rigid3d> predicted_cam_from_world;
  // Metres per current keypoint (<= 0 unknown), optional: with motion compensation a point whose
  // previous match has no depth is checked backwards, from its current depth into the previous
  // image.
  const std::vector<float>* depths = nullptr;
};

struct DynamicResult {
  std::vector<PointLabel> labels;  // kKept or one of the kDynamic* labels; inactive stay kKept
  std::vector<GrownBox> boxes;
  // Mean displacement of the t best background matches: (cur - prev), or with motion
  // compensation the mean residual (cur - fitted position of prev).
  std::optional<Eigen::Vector2d> background_motion;
  int num_background_matches = 0;   // used for background_motion (<= t)
  bool motion_compensated = false;  // stage 1 used the fitted camera motion
  int num_motion_inliers = 0;       // RANSAC inliers of that fit (or of the epipolar one)
  bool epipolar_fitted = false;     // `dynamic_test: epipolar` found the background's geometry
};

// The fundamental matrix (undistorted pixels, previous to current: x_cur^T F x_prev = 0) fitted to
// background correspondences, RANSAC at params.epipolar_px. nullopt with fewer than
// params.motion_min_inliers correspondences or inliers.
std::optional<Eigen::Matrix3d> FitBackgroundEpipolarGeometry(
    const std::vector<Eigen::Vector2d>& background_prev,
    const std::vector<Eigen::Vector2d>& background_cur, const DynamicParams& params,
    int* num_inliers = nullptr);

// The motion from the previous to the current camera, from `cur_from_prev` (a prediction) refined
// on background correspondences (undistorted pixels) by Gauss-Newton on their Sampson distances,
// Huber at `threshold_px`, points beyond three times it ignored. Rotation and the translation's
// direction only: the translation keeps its length. Unchanged with fewer than 8 points.
Rigid3d RefineMotionOnBackground(const Rigid3d& cur_from_prev,
                                 const std::vector<Eigen::Vector2d>& prev_px,
                                 const std::vector<Eigen::Vector2d>& cur_px, const Camera& camera,
                                 double threshold_px);

// F = K^-T [t]x R K^-1 of the motion (undistorted pixels, previous to current).
Eigen::Matrix3d FundamentalFromMotion(const Rigid3d& cur_from_prev, const Camera& camera);

// Distance (pixels) of the current point from the epipolar line of its previous match.
double EpipolarDistance(const Eigen::Matrix3d& fundamental, const Eigen::Vector2d& prev_px,
                        const Eigen::Vector2d& cur_px);

DynamicResult RemoveDynamicPoints(const DynamicInput& input, const DynamicParams& params);

// The motion from the previous to the current camera fitted to the matches whose current point is
// outside every box (in_box[query] == 0) and whose previous point has a camera-frame position:
// EPnP in RANSAC, then Levenberg-Marquardt on the inliers. nullopt with fewer than
// params.motion_min_inliers points or inliers. matches: queryIdx current, trainIdx previous.
std::optional<Rigid3d> FitBackgroundMotion(const std::vector<cv::KeyPoint>& keypoints,
                                           const PreviousFrameFeatures& previous,
                                           const std::vector<cv::DMatch>& matches,
                                           const std::vector<char>& in_box, const Camera& camera,
                                           const DynamicParams& params, int* num_inliers = nullptr);

}  // namespace ademono
