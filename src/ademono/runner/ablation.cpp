#include "ademono/runner/ablation.h"

#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "ademono/core/file_util.h"
#include "ademono/runner/run_writer.h"

namespace fs = std::filesystem;

namespace ademono {

const std::vector<AblationVariant>& DefaultAblationVariants() {
  static const std::vector<AblationVariant> variants{
      {"full", true, true, true},
      {"no_dynamic", true, false, true, false},
      {"no_distant", true, true, false},
      {"no_dynamic_no_distant", true, false, false, false},
      {"no_enhancement", false, true, true},
  };
  return variants;
}

const std::vector<AblationVariant>& AllAblationVariants() {
  static const std::vector<AblationVariant> variants = [] {
    std::vector<AblationVariant> v = DefaultAblationVariants();
    v.push_back({"boxes_only", true, true, true, false, true, true});
    v.push_back({"geometry_only", true, true, true, true, false});
    return v;
  }();
  return variants;
}

std::vector<std::string> AblationSetOverrides(const AblationVariant& variant) {
  auto flag = [](bool on) { return std::string(on ? "true" : "false"); };
  std::vector<std::string> sets = {
      "filter.enable_enhancement=" + flag(variant.enhancement),
      "filter.enable_dynamic_removal=" + flag(variant.dynamic_removal),
      "filter.enable_distant_filter=" + flag(variant.distant_filter),
      "tracking.static_test=" + flag(variant.geometric_test)};
  if (variant.paper_small_boxes) sets.push_back("filter.judge_small_boxes=false");
  return sets;
}

const AblationVariant* FindAblationVariant(const std::string& name) {
  for (const AblationVariant& v : AllAblationVariants()) {
    if (v.name == name) return &v;
  }
  return nullptr;
}

nlohmann::json VariantResult::ToJson() const {
  auto opt = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  nlohmann::json j;
  j["variant"] = variant.name;
  j["filters"] = {{"enhancement", variant.enhancement},
                  {"dynamic_removal", variant.dynamic_removal},
                  {"distant", variant.distant_filter},
                  {"geometric_test", variant.geometric_test},
                  {"detector", variant.use_detector},
                  {"paper_small_boxes", variant.paper_small_boxes}};
  j["frames"] = frames;
  j["tracked"] = tracked;
  j["tracking_rate"] = frames > 0 ? static_cast<double>(tracked) / frames : 0.0;
  j["lost"] = lost;
  j["keyframes"] = keyframes;
  j["map_points"] = map_points;
  j["ate_se3_rmse_m"] = opt(ate_se3_m);
  j["ate_sim3_rmse_m"] = opt(ate_sim3_m);
  j["sim3_scale"] = opt(sim3_scale);
  if (!note.empty()) j["note"] = note;
  j["filter_counts"] = filters.ToJson();
  j["truth"] = truth ? truth->ToJson() : nlohmann::json(nullptr);
  j["wall_seconds"] = wall_seconds;
  return j;
}

VariantResult RunAblationVariant(const Sequence& sequence, DepthProvider* depth, Detector* detector,
                                 const AblationOptions& options, const AblationVariant& variant,
                                 const fs::path& out_dir) {
  RunOptions run;
  run.system = options.system;
  run.system.filter.enable_enhancement = variant.enhancement;
  run.system.filter.enable_dynamic_removal = variant.dynamic_removal;
  run.system.filter.enable_distant_filter = variant.distant_filter;
  run.system.tracking.static_test = variant.geometric_test;
  if (variant.paper_small_boxes) run.system.filter.dynamic.judge_small_boxes = false;
  run.pipeline = options.pipeline;
  run.dataset = options.dataset;
  run.config = options.config;
  run.detector = options.detector;
  run.score_synthetic_truth = options.score_synthetic_truth;
  if (options.on_frame) {
    run.on_frame = [&](const FrameData& frame, const std::vector<Detection>& detections,
                       const TrackResult& r) { options.on_frame(variant, frame, detections, r); };
  }
  const RunReport report =
      RunSequence(sequence, depth, variant.use_detector ? detector : nullptr, run);
  WriteRunOutputs(report, out_dir);

  VariantResult result;
  result.variant = variant;
  result.frames = report.frames;
  result.tracked = report.Tracked();
  result.lost = report.lost;
  result.keyframes = report.keyframes;
  result.map_points = report.map_points;
  result.wall_seconds = report.wall_seconds;
  result.filters = report.filter_totals;
  result.truth = report.truth;
  if (report.accuracy) {
    result.ate_se3_m = report.accuracy->ate_se3_rmse_m;
    result.ate_sim3_m = report.accuracy->ate_sim3_rmse_m;
    result.sim3_scale = report.accuracy->sim3_scale;
  } else {
    result.note = report.accuracy_note;
  }
  return result;
}

std::string AblationMarkdown(const std::vector<VariantResult>& results) {
  std::ostringstream os;
  auto num = [](const std::optional<double>& v, int precision) {
    if (!v) return std::string("n/a");
    std::ostringstream s;
    s << std::fixed << std::setprecision(precision) << *v;
    return s.str();
  };
  const bool truth = !results.empty() && results.front().truth.has_value();
  os << "| variant | enh | dyn | dist | geo | boxes | ATE se3 (m) | ATE sim3 (m) | tracked | "
        "keyframes | "
        "removed enh | removed dyn (small/st1/st2/vote) | removed distant (of >Z_th) |";
  if (truth)
    os << " moving removed | moving kept out of tracking and map | unboxed moving removed | "
          "static removed | static person removed |";
  os << "\n|---|---|---|---|---|---|---|---|---|---|---|---|---|";
  if (truth) os << "---|---|---|---|---|";
  os << "\n";
  auto onoff = [](bool b) { return b ? "on" : "off"; };
  for (const VariantResult& r : results) {
    const FilterTotals& f = r.filters;
    os << "| " << r.variant.name << " | " << onoff(r.variant.enhancement) << " | "
       << onoff(r.variant.dynamic_removal) << " | " << onoff(r.variant.distant_filter) << " | "
       << onoff(r.variant.geometric_test) << " | " << onoff(r.variant.use_detector) << " | "
       << num(r.ate_se3_m, 4) << " | " << num(r.ate_sim3_m, 4) << " | " << r.tracked << "/"
       << r.frames << " | " << r.keyframes << " | " << f.removed_enhancement << " | "
       << f.RemovedDynamic() << " (" << f.removed_small_box << "/" << f.removed_stage1 << "/"
       << f.removed_stage2 << "/" << f.removed_box_vote << ") | " << f.removed_distant << " (of "
       << f.distant_candidates << ") |";
    if (truth) {
      auto pct = [](long long a, long long b) {
        if (b == 0) return std::string("n/a");
        std::ostringstream s;
        s << std::fixed << std::setprecision(1) << 100.0 * a / b << "% (" << a << "/" << b << ")";
        return s.str();
      };
      const TruthCounts t = r.truth.value_or(TruthCounts{});
      // Kept out: not a pose inlier, and no new map point of it ever admitted (synthetic_truth.h).
      os << " " << pct(t.moving_removed, t.moving_keypoints) << " | "
         << pct(t.moving_keypoints - t.MovingEntered(), t.moving_keypoints) << " | "
         << pct(t.moving_unboxed_removed, t.moving_unboxed_keypoints) << " | "
         << pct(t.static_removed, t.static_keypoints) << " | "
         << pct(t.static_person_removed, t.static_person_keypoints) << " |";
    }
    os << "\n";
  }
  for (const VariantResult& r : results) {
    if (!r.note.empty()) os << "\n" << r.variant.name << ": " << r.note << "\n";
  }
  return os.str();
}

nlohmann::json AblationJson(const std::vector<VariantResult>& results) {
  nlohmann::json j = nlohmann::json::array();
  for (const VariantResult& r : results) j.push_back(r.ToJson());
  return {{"variants", j}};
}

std::vector<VariantResult> RunAblation(const Sequence& sequence, DepthProvider* depth,
                                       Detector* detector, const AblationOptions& options,
                                       const fs::path& out_dir) {
  if (options.variants.empty()) throw std::invalid_argument("RunAblation: no variants");
  std::vector<VariantResult> results;
  for (const AblationVariant& v : options.variants) {
    results.push_back(RunAblationVariant(sequence, depth, detector, options, v, out_dir / v.name));
  }
  nlohmann::json json = AblationJson(results);
  json["dataset"] = sequence.Kind() + ":" + sequence.Path().string();
  json["depth"] = depth != nullptr ? depth->Name() : "none";
  json["detector"] = detector != nullptr ? detector->Name() : "none";
  WriteTextFileAtomic(out_dir / "ablation.json", json.dump(2) + "\n");
  WriteTextFileAtomic(out_dir / "ablation.md", AblationMarkdown(results));
  return results;
}

}  // namespace ademono
