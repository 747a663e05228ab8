#pragma once
// Dynamic interference removal (filter 2). Detections of dynamic classes are grown by a margin;
// points in small boxes are dropped outright, points in large boxes go through a two-stage test:
// (1) their frame-to-frame displacement against the background's, (2) the reprojection error of
// their previous world point under the constant-velocity pose prediction. See docs/filters.md.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "ademono/core/camera.h"
#include "ademono/core/geometry.h"
#include "ademono/detect/detection.h"
#include "ademono/filter/feature_filter.h"

namespace ademono {

struct DynamicParams {
  double box_growth = 0.02;
  double small_box_area_ratio = 0.05;
  int background_matches_t = 20;
  double d_dis_px = 8.0;
  double d_min_px = 4.0;
  // Box vote for unmatched large-box points: a box is moving when at least this fraction of its
  // matched points (and at least box_vote_min_matches of them) failed stage 1 or 2. > 1 disables.
  double box_vote_ratio = 0.15;
  int box_vote_min_matches = 5;
  std::vector<int> dynamic_class_ids = DefaultDynamicClassIds();
  // Frame-to-frame matching for stage 1 (not in FilterOptions: ORB-SLAM's usual values).
  double match_ratio = 0.8;
  int match_max_distance = 100;
};

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
};

struct DynamicResult {
  std::vector<PointLabel> labels;  // kKept or one of the kDynamic* labels; inactive stay kKept
  std::vector<GrownBox> boxes;
  std::optional<Eigen::Vector2d> background_motion;  // mean (cur - prev) of the t best matches
  int num_background_matches = 0;                    // used for background_motion (<= t)
};

DynamicResult RemoveDynamicPoints(const DynamicInput& input, const DynamicParams& params);

}  // namespace ademono
