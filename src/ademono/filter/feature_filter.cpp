#include "ademono/filter/feature_filter.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "ademono/core/yaml_util.h"
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

void DynamicParams::Check() const {
  Require(box_growth >= 0 && box_growth <= 1,
          "box_growth must be in [0, 1], got " + std::to_string(box_growth));
  Require(small_box_area_ratio >= 0 && small_box_area_ratio <= 1,
          "small_box_area_ratio must be in [0, 1], got " + std::to_string(small_box_area_ratio));
  Require(background_matches_t >= 1,
          "background_matches_t must be >= 1, got " + std::to_string(background_matches_t));
  Require(d_dis_px > 0 && std::isfinite(d_dis_px),
          "d_dis_px must be > 0, got " + std::to_string(d_dis_px));
  Require(d_min_px > 0 && std::isfinite(d_min_px),
          "d_min_px must be > 0, got " + std::to_string(d_min_px));
  Require(
      box_vote_ratio >= 0 && std::isfinite(box_vote_ratio),
      "box_vote_ratio must be >= 0 (> 1 disables the vote), got " + std::to_string(box_vote_ratio));
  Require(box_vote_min_matches >= 1,
          "box_vote_min_matches must be >= 1, got " + std::to_string(box_vote_min_matches));
  Require(motion_min_inliers >= 4,
          "motion_min_inliers must be >= 4, got " + std::to_string(motion_min_inliers));
  Require(motion_inlier_px > 0 && std::isfinite(motion_inlier_px),
          "motion_inlier_px must be > 0, got " + std::to_string(motion_inlier_px));
  Require(motion_ransac_iterations >= 1,
          "motion_ransac_iterations must be >= 1, got " + std::to_string(motion_ransac_iterations));
}

void FilterOptions::Check() const {
  Require(
      enhancement_keep_ratio > 0 && enhancement_keep_ratio <= 1,
      "enhancement_keep_ratio must be in (0, 1], got " + std::to_string(enhancement_keep_ratio));
  Require(enhancement_levels >= 0 && enhancement_levels <= 6,
          "enhancement_levels must be in [0, 6], got " + std::to_string(enhancement_levels));
  Require(std::isfinite(enhancement_p_percent) && enhancement_p_percent != 0,
          "enhancement_p_percent must be > 0 (or < 0 for the default), got " +
              std::to_string(enhancement_p_percent));
  Require(std::isfinite(enhancement_q_percent) && enhancement_q_percent != 0,
          "enhancement_q_percent must be > 0 (or < 0 for the default), got " +
              std::to_string(enhancement_q_percent));
  dynamic.Check();
  Require(z_th_m > 0 && std::isfinite(z_th_m), "z_th_m must be > 0, got " + std::to_string(z_th_m));
  Require(drop_probability >= 0 && drop_probability <= 1,
          "drop_probability must be in [0, 1], got " + std::to_string(drop_probability));
}

FilterOptions FilterOptions::FromYaml(const YAML::Node& node) {
  FilterOptions o;
  if (!node || node.IsNull()) return o;
  if (!node.IsMap()) throw std::invalid_argument("filter: expected a map of options");
  // A misspelt key would silently keep its default: reject it.
  CheckYamlKeys(node, "filter",
                {"enable_enhancement",
                 "enable_dynamic_removal",
                 "enable_distant_filter",
                 "enhancement_keep_ratio",
                 "enhancement_levels",
                 "enhancement_p_percent",
                 "enhancement_q_percent",
                 "box_growth",
                 "small_box_area_ratio",
                 "background_matches_t",
                 "d_dis_px",
                 "d_min_px",
                 "stage1_motion_compensation",
                 "box_vote_ratio",
                 "box_vote_min_matches",
                 "dynamic_class_ids",
                 "motion_min_inliers",
                 "motion_inlier_px",
                 "motion_ransac_iterations",
                 "z_th_m",
                 "drop_probability",
                 "seed"});
  o.enable_enhancement = ReadYamlKey(node, "filter", "enable_enhancement", o.enable_enhancement);
  o.enable_dynamic_removal =
      ReadYamlKey(node, "filter", "enable_dynamic_removal", o.enable_dynamic_removal);
  o.enable_distant_filter =
      ReadYamlKey(node, "filter", "enable_distant_filter", o.enable_distant_filter);
  o.enhancement_keep_ratio =
      ReadYamlKey(node, "filter", "enhancement_keep_ratio", o.enhancement_keep_ratio);
  o.enhancement_levels = ReadYamlKey(node, "filter", "enhancement_levels", o.enhancement_levels);
  o.enhancement_p_percent =
      ReadYamlKey(node, "filter", "enhancement_p_percent", o.enhancement_p_percent);
  o.enhancement_q_percent =
      ReadYamlKey(node, "filter", "enhancement_q_percent", o.enhancement_q_percent);
  o.dynamic.box_growth = ReadYamlKey(node, "filter", "box_growth", o.dynamic.box_growth);
  o.dynamic.small_box_area_ratio =
      ReadYamlKey(node, "filter", "small_box_area_ratio", o.dynamic.small_box_area_ratio);
  o.dynamic.background_matches_t =
      ReadYamlKey(node, "filter", "background_matches_t", o.dynamic.background_matches_t);
  o.dynamic.d_dis_px = ReadYamlKey(node, "filter", "d_dis_px", o.dynamic.d_dis_px);
  o.dynamic.d_min_px = ReadYamlKey(node, "filter", "d_min_px", o.dynamic.d_min_px);
  o.dynamic.stage1_motion_compensation = ReadYamlKey(node, "filter", "stage1_motion_compensation",
                                                     o.dynamic.stage1_motion_compensation);
  o.dynamic.box_vote_ratio =
      ReadYamlKey(node, "filter", "box_vote_ratio", o.dynamic.box_vote_ratio);
  o.dynamic.box_vote_min_matches =
      ReadYamlKey(node, "filter", "box_vote_min_matches", o.dynamic.box_vote_min_matches);
  o.dynamic.dynamic_class_ids =
      ReadYamlKey(node, "filter", "dynamic_class_ids", o.dynamic.dynamic_class_ids);
  o.dynamic.motion_min_inliers =
      ReadYamlKey(node, "filter", "motion_min_inliers", o.dynamic.motion_min_inliers);
  o.dynamic.motion_inlier_px =
      ReadYamlKey(node, "filter", "motion_inlier_px", o.dynamic.motion_inlier_px);
  o.dynamic.motion_ransac_iterations =
      ReadYamlKey(node, "filter", "motion_ransac_iterations", o.dynamic.motion_ransac_iterations);
  o.z_th_m = ReadYamlKey(node, "filter", "z_th_m", o.z_th_m);
  o.drop_probability = ReadYamlKey(node, "filter", "drop_probability", o.drop_probability);
  o.seed = ReadYamlKey(node, "filter", "seed", o.seed);
  o.Check();
  return o;
}

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
    s.stage1_ran = result.background_motion.has_value() ? 1 : 0;
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
