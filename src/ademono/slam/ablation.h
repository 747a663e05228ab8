#pragma once
// The paper's filter ablation: the same sequence, depth and detections run through the SLAM
// pipeline with the filters switched on and off, compared by ATE against the dataset's ground
// truth, tracking rate, keyframes and what each filter removed. Used by `ademono ablate`.
//
// On a synthetic sequence (`ademono synth`: masks/<name>.png of moving objects) the per-keypoint
// filter labels are also scored against the truth: how many keypoints on moving objects were
// removed, and how many on a static person-class object (the office mannequin).

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ademono/depth/depth_provider.h"
#include "ademono/detect/detection.h"
#include "ademono/filter/feature_filter.h"
#include "ademono/io/sequence.h"
#include "ademono/io/trajectory.h"
#include "ademono/slam/options.h"
#include "ademono/slam/pipeline.h"

namespace ademono {

struct AblationVariant {
  std::string name;  // directory name below the output directory
  bool enhancement = true;
  bool dynamic_removal = true;
  bool distant_filter = true;
};
// full, no_dynamic, no_distant, no_dynamic_no_distant, no_enhancement.
const std::vector<AblationVariant>& DefaultAblationVariants();

// Sum of the per-frame filter statistics.
struct FilterTotals {
  long long boxes_small = 0, boxes_large = 0;
  long long removed_enhancement = 0, removed_small_box = 0, removed_stage1 = 0, removed_stage2 = 0;
  long long removed_box_vote = 0;
  long long removed_distant = 0, distant_candidates = 0, kept = 0, keypoints = 0;
  long long stage1_frames = 0, stage1_compensated_frames = 0;
  void Add(const FilterStats& s, int num_keypoints);
  long long RemovedDynamic() const {
    return removed_small_box + removed_stage1 + removed_stage2 + removed_box_vote;
  }
  nlohmann::json ToJson() const;
};
nlohmann::json FilterStatsJson(const FilterStats& s);

// Keypoints scored against synthetic ground truth. Only keypoints that reach the dynamic filter
// count (not dropped by the enhancement before it), and only dynamic-removal labels count as
// removed (a distant drop is not the dynamic filter's doing).
struct TruthCounts {
  long long moving_keypoints = 0;         // keypoints whose pixel is in the moving-object mask
  long long moving_removed = 0;           // ... labelled dynamic
  long long moving_kept = 0;              // ... labelled kept (used for tracking)
  long long static_person_keypoints = 0;  // in the static person box, not on a moving object
  long long static_person_removed = 0;    // ... labelled dynamic
  // In any box of a dynamic class (the detector's box, not grown) but not on a moving object:
  // static objects such as parked cars, and background seen inside boxes.
  long long static_in_box_keypoints = 0;
  long long static_in_box_removed = 0;  // ... labelled dynamic
  nlohmann::json ToJson() const;
};

// Reads masks/<frame name>.png of a synthetic sequence and finds the static person box of a
// frame (a person box with under 20% moving pixels; the mannequin). Available() is false when
// the sequence has no masks/ folder.
class SyntheticTruth {
 public:
  explicit SyntheticTruth(const std::filesystem::path& sequence_dir);
  bool Available() const { return available_; }
  // Throws InputError when the frame's mask is missing or not the image size.
  void Score(const FrameData& frame, const std::vector<Detection>& detections,
             const std::vector<cv::KeyPoint>& keypoints, const std::vector<PointLabel>& labels,
             TruthCounts* counts) const;

 private:
  std::filesystem::path masks_dir_;
  bool available_ = false;
};

struct VariantResult {
  AblationVariant variant;
  size_t frames = 0, tracked = 0, keyframes = 0, map_points = 0;
  int lost = 0;
  std::optional<double> ate_se3_m, ate_sim3_m, sim3_scale;
  std::string note;  // why the ATE is missing, if it is
  FilterTotals filters;
  std::optional<TruthCounts> truth;
  double wall_seconds = 0;
  nlohmann::json ToJson() const;
};

struct AblationOptions {
  SystemOptions system;  // the variant flags override system.filter.enable_*
  PipelineOptions pipeline;
  std::vector<AblationVariant> variants = DefaultAblationVariants();
  bool score_synthetic_truth = true;  // when the sequence has masks/
  // Called after each frame of each variant (e.g. progress, --viz).
  std::function<void(const AblationVariant&, const FrameData&, const std::vector<Detection>&,
                     const TrackResult&)>
      on_frame;
};

// Runs one variant and writes its run outputs (trajectory.tum, trajectory.kitti, keyframes.tum,
// summary.json, each atomically) into `out_dir` (created). `depth` / `detector` are shared by the
// variants: providers are deterministic per frame.
VariantResult RunAblationVariant(const Sequence& sequence, DepthProvider* depth, Detector* detector,
                                 const AblationOptions& options, const AblationVariant& variant,
                                 const std::filesystem::path& out_dir);

// Runs every variant into out_dir/<name>/ and writes out_dir/ablation.md and
// out_dir/ablation.json. Returns the per-variant results in the order of options.variants.
std::vector<VariantResult> RunAblation(const Sequence& sequence, DepthProvider* depth,
                                       Detector* detector, const AblationOptions& options,
                                       const std::filesystem::path& out_dir);

std::string AblationMarkdown(const std::vector<VariantResult>& results);
nlohmann::json AblationJson(const std::vector<VariantResult>& results);

}  // namespace ademono
