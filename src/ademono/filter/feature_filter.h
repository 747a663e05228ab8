#pragma once
// The method's three per-frame filters, applied in order to the ORB keypoints of a frame before
// tracking: (1) depth-weighted feature enhancement, (2) dynamic interference removal,
// (3) distant-point filtering. Each can be switched off (the paper's ablation).
// Keypoints labelled anything but kKept are never used for pose estimation or as map points.

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "ademono/core/camera.h"
#include "ademono/core/geometry.h"
#include "ademono/filter/dynamic_params.h"
#include "ademono/perception/detection.h"

namespace ademono {

enum class PointLabel : uint8_t {
  kKept = 0,
  kEnhancementDropped,  // not chosen by the depth-weighted quadtree selection
  kDynamicSmallBox,     // inside a grown small-target box
  kDynamicStage1,       // large box, displacement differs from background by > D_dis
  kDynamicStage2,       // large box, reprojection error under constant velocity > D_min
  kDistantDropped,      // deeper than Z_th and drawn for dropping
  kDynamicBoxVote,      // large box, unmatched, in a box whose matched points mostly moved
};
inline constexpr int kNumPointLabels = 7;
static_assert(static_cast<int>(PointLabel::kDynamicBoxVote) + 1 == kNumPointLabels,
              "kNumPointLabels must follow the last label");
const char* PointLabelName(PointLabel label);
// A label of dynamic interference removal (small box, stage 1, stage 2, box vote): the point
// lies on something the filter judged to move.
constexpr bool IsDynamic(PointLabel label) {
  return label == PointLabel::kDynamicSmallBox || label == PointLabel::kDynamicStage1 ||
         label == PointLabel::kDynamicStage2 || label == PointLabel::kDynamicBoxVote;
}

struct FilterOptions {
  bool enable_enhancement = true;
  bool enable_dynamic_removal = true;
  bool enable_distant_filter = true;
  // Enhancement: fraction of a block's points kept, quadtree depth (levels of 4-way split).
  double enhancement_keep_ratio = 0.75;
  int enhancement_levels = 2;
  // P and Q (percent) scale the weight; documented in docs/filters.md.
  double enhancement_p_percent = -1;  // < 0: derived from the image size
  double enhancement_q_percent = -1;
  DynamicParams dynamic;  // dynamic removal (filter/dynamic_params.h)
  // Distant filter.
  double z_th_m = 30.0;
  double drop_probability = 0.5;
  // false (the paper's rule): a drawn far point is removed. true: only its depth is dropped; the
  // keypoint still matches map points as a bearing (rotation) but makes no new point.
  bool distant_keep_bearing = false;
  uint64_t seed = 42;

  void Check() const;                                     // throws std::invalid_argument
  static FilterOptions FromYaml(const YAML::Node& node);  // the `filter:` sub-node
  YAML::Node ToYaml() const;
  static const OptionsTable<FilterOptions>& Table();  // core/options_table.h
  bool operator==(const FilterOptions&) const = default;
};

// Whether a keypoint with this label goes on to tracking: kept ones, and with
// `distant_keep_bearing` the distant-dropped ones (without their depth).
inline bool FeedsTracking(PointLabel label, const FilterOptions& options) {
  return label == PointLabel::kKept ||
         (options.distant_keep_bearing && label == PointLabel::kDistantDropped);
}

// What the filter needs of the previous frame for the two-stage dynamic test.
struct PreviousFrameFeatures {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  // World position of each keypoint (from its depth and the frame's estimated pose); NaN if none.
  std::vector<Eigen::Vector3d> points_world;
  // Position of each keypoint in that frame's camera, from its depth alone (known even when the
  // frame was not tracked); NaN if no depth. Empty: stage 1 cannot compensate the camera motion.
  std::vector<Eigen::Vector3d> points_cam;
  // That frame's estimated pose, if it was tracked (the epipolar test's motion).
  std::optional<Rigid3d> cam_from_world;
};

struct FilterInput {
  const Camera* camera = nullptr;
  const std::vector<cv::KeyPoint>* keypoints = nullptr;
  const cv::Mat* descriptors = nullptr;
  const std::vector<float>* depths = nullptr;  // metres per keypoint, <= 0 when unknown
  const std::vector<Detection>* detections = nullptr;
  const PreviousFrameFeatures* previous = nullptr;  // null on the first frame
  std::optional<Rigid3d> predicted_cam_from_world;  // constant-velocity prediction
};

struct FilterStats {
  int boxes_small = 0;
  int boxes_large = 0;
  int removed_enhancement = 0;
  int removed_small_box = 0;
  int removed_stage1 = 0;
  int removed_stage2 = 0;
  int removed_box_vote = 0;
  int removed_distant = 0;
  // Points that reached the distant filter with a known depth above z_th (its candidates):
  // removed_distant / distant_candidates is the realised drop rate.
  int distant_candidates = 0;
  int kept = 0;
  // 1 when stage 1 ran this frame (a large box and a previous frame with background matches),
  // and when it compared against the camera motion fitted to the background (else the paper's
  // mean displacement).
  int stage1_ran = 0;
  int stage1_compensated = 0;
};

class FeatureFilter {
 public:
  explicit FeatureFilter(const FilterOptions& options);
  // One label per input keypoint. Deterministic given the options' seed and the call sequence.
  std::vector<PointLabel> Apply(const FilterInput& input, FilterStats* stats = nullptr);
  const FilterOptions& Options() const { return options_; }

 private:
  FilterOptions options_;
  std::mt19937_64 rng_;
};

}  // namespace ademono
