#include "ademono/filter/feature_filter.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "ademono/core/options_table.h"
#include "ademono/filter/distant.h"
#include "ademono/filter/dynamic.h"
#include "ademono/filter/enhancement.h"

namespace ademono {
namespace {

void Require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("filter." + message);
}

}  // namespace

const char* PointLabelName(PointLabel label) {
  switch (label) {
    case PointLabel::kKept:
      return "kept";
    case PointLabel::kEnhancementDropped:
      return "enhancement_dropped";
    case PointLabel::kDynamicSmallBox:
      return "dynamic_small_box";
    case PointLabel::kDynamicStage1:
      return "dynamic_stage1";
    case PointLabel::kDynamicStage2:
      return "dynamic_stage2";
    case PointLabel::kDistantDropped:
      return "distant_dropped";
    case PointLabel::kDynamicBoxVote:
      return "dynamic_box_vote";
  }
  return "unknown";
}

const OptionsTable<DynamicParams>& DynamicParams::Table() {
  using P = DynamicParams;
  static const auto table =
      OptionsTable<P>("filter")
          .Add("box_growth", &P::box_growth, Range::Closed(0, 1))
          .Add("small_box_area_ratio", &P::small_box_area_ratio, Range::Closed(0, 1))
          .Add("judge_small_boxes", &P::judge_small_boxes)
          .Add("background_matches_t", &P::background_matches_t, Range::AtLeast(1))
          .Add("d_dis_px", &P::d_dis_px, Range::Above(0))
          .Add("d_min_px", &P::d_min_px, Range::Above(0))
          .Add("stage1_motion_compensation", &P::stage1_motion_compensation)
          .Add("box_vote_ratio", &P::box_vote_ratio, Range::AtLeast(0))  // > 1 disables the vote
          .Add("box_vote_min_matches", &P::box_vote_min_matches, Range::AtLeast(1))
          .Add("box_vote_depth_ratio", &P::box_vote_depth_ratio, Range::AtLeast(0))  // 0: off
          .Add("dynamic_class_ids", &P::dynamic_class_ids)
          .Add("motion_min_inliers", &P::motion_min_inliers, Range::AtLeast(4))
          .Add("motion_inlier_px", &P::motion_inlier_px, Range::Above(0))
          .Add("motion_ransac_iterations", &P::motion_ransac_iterations, Range::AtLeast(1))
          .Add("dynamic_test", &P::dynamic_test)
          .Add("epipolar_px", &P::epipolar_px, Range::Above(0));
  return table;
}

void DynamicParams::Check() const {
  Table().CheckRanges(*this);
  Require(dynamic_test == "depth" || dynamic_test == "epipolar",
          "dynamic_test must be 'depth' or 'epipolar', got '" + dynamic_test + "'");
}

const OptionsTable<FilterOptions>& FilterOptions::Table() {
  using F = FilterOptions;
  static const auto table =
      OptionsTable<F>("filter")
          .Add("enable_enhancement", &F::enable_enhancement)
          .Add("enable_dynamic_removal", &F::enable_dynamic_removal)
          .Add("enable_distant_filter", &F::enable_distant_filter)
          .Add("enhancement_keep_ratio", &F::enhancement_keep_ratio, Range::OpenClosed(0, 1))
          .Add("enhancement_levels", &F::enhancement_levels, Range::Closed(0, 6))
          .Add("enhancement_p_percent", &F::enhancement_p_percent)
          .Add("enhancement_q_percent", &F::enhancement_q_percent)
          .AddFlat(&F::dynamic, DynamicParams::Table())
          .Add("z_th_m", &F::z_th_m, Range::Above(0))
          .Add("drop_probability", &F::drop_probability, Range::Closed(0, 1))
          .Add("distant_keep_bearing", &F::distant_keep_bearing)
          .Add("seed", &F::seed);
  return table;
}

void FilterOptions::Check() const {
  Table().CheckRanges(*this);
  dynamic.Check();
  Require(std::isfinite(enhancement_p_percent) && enhancement_p_percent != 0,
          "enhancement_p_percent must be > 0 (or < 0 for the default), got " +
              std::to_string(enhancement_p_percent));
  Require(std::isfinite(enhancement_q_percent) && enhancement_q_percent != 0,
          "enhancement_q_percent must be > 0 (or < 0 for the default), got " +
              std::to_string(enhancement_q_percent));
}

// A misspelt key would silently keep its default: the table rejects it.
FilterOptions FilterOptions::FromYaml(const YAML::Node& node) {
  return ReadOptions<FilterOptions>(node);
}

YAML::Node FilterOptions::ToYaml() const { return Table().Write(*this); }

FeatureFilter::FeatureFilter(const FilterOptions& options) : options_(options), rng_(options.seed) {
  options_.Check();
}

std::vector<PointLabel> FeatureFilter::Apply(const FilterInput& input, FilterStats* stats) {
  if (input.keypoints == nullptr) throw std::invalid_argument("FeatureFilter: keypoints missing");
  if (input.camera == nullptr) throw std::invalid_argument("FeatureFilter: camera missing");
  const std::vector<cv::KeyPoint>& kps = *input.keypoints;
  const size_t n = kps.size();
  if (input.depths != nullptr && input.depths->size() != n)
    throw std::invalid_argument("FeatureFilter: " + std::to_string(input.depths->size()) +
                                " depths for " + std::to_string(n) + " keypoints");
  if (input.descriptors != nullptr && !input.descriptors->empty() &&
      input.descriptors->rows != static_cast<int>(n))
    throw std::invalid_argument("FeatureFilter: descriptor rows do not match the keypoints");
  const cv::Size image_size(input.camera->width, input.camera->height);
  const std::vector<float> no_depths;
  const std::vector<float>& depths = input.depths != nullptr ? *input.depths : no_depths;

  std::vector<PointLabel> labels(n, PointLabel::kKept);
  auto kept_mask = [&] {
    std::vector<bool> active(n);
    for (size_t i = 0; i < n; ++i) active[i] = labels[i] == PointLabel::kKept;
    return active;
  };
  FilterStats s;

  if (options_.enable_enhancement) {
    std::vector<cv::Point2f> points(n);
    for (size_t i = 0; i < n; ++i) points[i] = kps[i].pt;
    EnhancementParams params;
    params.keep_ratio = options_.enhancement_keep_ratio;
    params.levels = options_.enhancement_levels;
    params.p_percent = options_.enhancement_p_percent;
    params.q_percent = options_.enhancement_q_percent;
    const std::vector<bool> selected =
        SelectEnhancedFeatures(points, depths, {}, image_size, params);
    for (size_t i = 0; i < n; ++i)
      if (!selected[i]) labels[i] = PointLabel::kEnhancementDropped;
  }

  if (options_.enable_dynamic_removal) {
    DynamicInput dyn;
    dyn.keypoints = &kps;
    dyn.descriptors = input.descriptors;
    dyn.active = kept_mask();
    dyn.detections = input.detections;
    dyn.previous = input.previous;
    dyn.camera = input.camera;
    dyn.predicted_cam_from_world = input.predicted_cam_from_world;
    dyn.depths = input.depths;
    const DynamicResult result = RemoveDynamicPoints(dyn, options_.dynamic);
    for (size_t i = 0; i < n; ++i)
      if (labels[i] == PointLabel::kKept) labels[i] = result.labels[i];
    for (const GrownBox& b : result.boxes) (b.small ? s.boxes_small : s.boxes_large)++;
    s.stage1_ran = result.background_motion.has_value() || result.epipolar_fitted ? 1 : 0;
    s.stage1_compensated = s.stage1_ran && result.motion_compensated ? 1 : 0;
  }

  if (options_.enable_distant_filter && !depths.empty()) {
    const std::vector<bool> active = kept_mask();
    for (size_t i = 0; i < n; ++i) {
      if (active[i] && std::isfinite(depths[i]) && depths[i] > options_.z_th_m)
        ++s.distant_candidates;
    }
    const std::vector<bool> drop =
        DrawDistantDrops(depths, active, options_.z_th_m, options_.drop_probability, rng_);
    for (size_t i = 0; i < n; ++i)
      if (drop[i]) labels[i] = PointLabel::kDistantDropped;
  }

  for (PointLabel label : labels) {
    switch (label) {
      case PointLabel::kKept:
        ++s.kept;
        break;
      case PointLabel::kEnhancementDropped:
        ++s.removed_enhancement;
        break;
      case PointLabel::kDynamicSmallBox:
        ++s.removed_small_box;
        break;
      case PointLabel::kDynamicStage1:
        ++s.removed_stage1;
        break;
      case PointLabel::kDynamicStage2:
        ++s.removed_stage2;
        break;
      case PointLabel::kDistantDropped:
        ++s.removed_distant;
        break;
      case PointLabel::kDynamicBoxVote:
        ++s.removed_box_vote;
        break;
    }
  }
  if (stats != nullptr) *stats = s;
  return labels;
}

}  // namespace ademono
