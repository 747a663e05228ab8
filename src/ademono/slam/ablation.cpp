#include "ademono/slam/ablation.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/eval/trajectory_eval.h"
#include "ademono/slam/system.h"

namespace fs = std::filesystem;

namespace ademono {

const std::vector<AblationVariant>& DefaultAblationVariants() {
  static const std::vector<AblationVariant> variants{
      {"full", true, true, true},
      {"no_dynamic", true, false, true},
      {"no_distant", true, true, false},
      {"no_dynamic_no_distant", true, false, false},
      {"no_enhancement", false, true, true},
  };
  return variants;
}

void FilterTotals::Add(const FilterStats& s, int num_keypoints) {
  boxes_small += s.boxes_small;
  boxes_large += s.boxes_large;
  removed_enhancement += s.removed_enhancement;
  removed_small_box += s.removed_small_box;
  removed_stage1 += s.removed_stage1;
  removed_stage2 += s.removed_stage2;
  removed_box_vote += s.removed_box_vote;
  removed_distant += s.removed_distant;
  distant_candidates += s.distant_candidates;
  kept += s.kept;
  keypoints += num_keypoints;
  stage1_frames += s.stage1_ran;
  stage1_compensated_frames += s.stage1_compensated;
}

nlohmann::json FilterTotals::ToJson() const {
  nlohmann::json j{{"keypoints", keypoints},
                   {"kept", kept},
                   {"boxes_small", boxes_small},
                   {"boxes_large", boxes_large},
                   {"removed_enhancement", removed_enhancement},
                   {"removed_small_box", removed_small_box},
                   {"removed_stage1", removed_stage1},
                   {"removed_stage2", removed_stage2},
                   {"removed_box_vote", removed_box_vote},
                   {"removed_dynamic", RemovedDynamic()},
                   {"removed_distant", removed_distant},
                   {"distant_candidates", distant_candidates},
                   {"stage1_frames", stage1_frames},
                   {"stage1_compensated_frames", stage1_compensated_frames}};
  j["distant_drop_rate"] =
      distant_candidates > 0
          ? nlohmann::json(static_cast<double>(removed_distant) / distant_candidates)
          : nlohmann::json(nullptr);
  return j;
}

nlohmann::json FilterStatsJson(const FilterStats& s) {
  return {{"boxes_small", s.boxes_small},
          {"boxes_large", s.boxes_large},
          {"removed_enhancement", s.removed_enhancement},
          {"removed_small_box", s.removed_small_box},
          {"removed_stage1", s.removed_stage1},
          {"removed_stage2", s.removed_stage2},
          {"removed_box_vote", s.removed_box_vote},
          {"removed_distant", s.removed_distant},
          {"distant_candidates", s.distant_candidates},
          {"stage1_compensated", s.stage1_compensated},
          {"kept", s.kept}};
}

nlohmann::json TruthCounts::ToJson() const {
  auto ratio = [](long long a, long long b) {
    return b > 0 ? nlohmann::json(static_cast<double>(a) / b) : nlohmann::json(nullptr);
  };
  return {{"moving_keypoints", moving_keypoints},
          {"moving_removed", moving_removed},
          {"moving_kept", moving_kept},
          {"moving_removed_ratio", ratio(moving_removed, moving_keypoints)},
          {"static_person_keypoints", static_person_keypoints},
          {"static_person_removed", static_person_removed},
          {"static_person_removed_ratio", ratio(static_person_removed, static_person_keypoints)},
          {"static_in_box_keypoints", static_in_box_keypoints},
          {"static_in_box_removed", static_in_box_removed},
          {"static_in_box_removed_ratio", ratio(static_in_box_removed, static_in_box_keypoints)}};
}

SyntheticTruth::SyntheticTruth(const fs::path& sequence_dir) : masks_dir_(sequence_dir / "masks") {
  available_ = fs::is_directory(masks_dir_);
}

namespace {

cv::Point Pixel(const cv::KeyPoint& kp, const cv::Size& size) {
  return {std::clamp(static_cast<int>(std::lround(kp.pt.x)), 0, size.width - 1),
          std::clamp(static_cast<int>(std::lround(kp.pt.y)), 0, size.height - 1)};
}

}  // namespace

void SyntheticTruth::Score(const FrameData& frame, const std::vector<Detection>& detections,
                           const std::vector<cv::KeyPoint>& keypoints,
                           const std::vector<PointLabel>& labels, TruthCounts* counts) const {
  const fs::path path = masks_dir_ / (frame.name + ".png");
  RequireFile(path);
  const cv::Mat mask = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  if (mask.empty()) ThrowInputError(path, "cannot decode the mask image");
  if (!frame.image.empty() && mask.size() != frame.image.size())
    ThrowInputError(path, "mask size differs from the image size");
  // The static person: the person box with the fewest moving pixels, if under 20%.
  std::optional<cv::Rect> static_box;
  double best = 0.2;
  const cv::Rect bounds(0, 0, mask.cols, mask.rows);
  for (const Detection& d : detections) {
    if (d.class_id != 0) continue;
    const cv::Rect box = cv::Rect(d.box) & bounds;
    if (box.area() == 0) continue;
    const double moving = cv::countNonZero(mask(box) > 127) / static_cast<double>(box.area());
    if (moving < best) {
      best = moving;
      static_box = box;
    }
  }
  for (size_t i = 0; i < keypoints.size() && i < labels.size(); ++i) {
    const cv::Point p = Pixel(keypoints[i], mask.size());
    // Only keypoints the dynamic filter judged: enhancement drops happen before it.
    if (labels[i] == PointLabel::kEnhancementDropped) continue;
    const bool dynamic = IsDynamic(labels[i]);
    if (mask.at<uint8_t>(p) > 127) {
      ++counts->moving_keypoints;
      if (dynamic) ++counts->moving_removed;
      if (labels[i] == PointLabel::kKept) ++counts->moving_kept;
    } else {
      if (static_box && static_box->contains(p)) {
        ++counts->static_person_keypoints;
        if (dynamic) ++counts->static_person_removed;
      }
      const auto& classes = DefaultDynamicClassIds();
      const bool in_box =
          std::any_of(detections.begin(), detections.end(), [&](const Detection& d) {
            return std::find(classes.begin(), classes.end(), d.class_id) != classes.end() &&
                   d.box.contains(cv::Point2f(static_cast<float>(p.x), static_cast<float>(p.y)));
          });
      if (in_box) {
        ++counts->static_in_box_keypoints;
        if (dynamic) ++counts->static_in_box_removed;
      }
    }
  }
}

nlohmann::json VariantResult::ToJson() const {
  auto opt = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  nlohmann::json j;
  j["variant"] = variant.name;
  j["filters"] = {{"enhancement", variant.enhancement},
                  {"dynamic_removal", variant.dynamic_removal},
                  {"distant", variant.distant_filter}};
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
  SystemOptions system_options = options.system;
  system_options.filter.enable_enhancement = variant.enhancement;
  system_options.filter.enable_dynamic_removal = variant.dynamic_removal;
  system_options.filter.enable_distant_filter = variant.distant_filter;
  System system(sequence.GetCamera(), system_options);

  VariantResult result;
  result.variant = variant;
  const SyntheticTruth truth(sequence.Path());
  const bool score = options.score_synthetic_truth && truth.Available();
  if (score) result.truth = TruthCounts{};
  nlohmann::json per_frame = nlohmann::json::array();
  PipelineOptions pipeline = options.pipeline;
  pipeline.on_frame = [&](const FrameData& frame, const cv::Mat&,
                          const std::vector<Detection>& detections, const TrackResult& r) {
    result.filters.Add(r.filter_stats, r.num_keypoints);
    nlohmann::json f = FilterStatsJson(r.filter_stats);
    f["frame"] = frame.index;
    f["keypoints"] = r.num_keypoints;
    f["tracked"] = r.tracked;
    per_frame.push_back(std::move(f));
    if (score) truth.Score(frame, detections, r.keypoints, r.labels, &*result.truth);
    if (options.on_frame) options.on_frame(variant, frame, detections, r);
  };
  const PipelineResult run = RunPipeline(sequence, depth, detector, system, pipeline);
  system.Shutdown();

  const Trajectory trajectory = system.FrameTrajectory();
  result.frames = run.frames;
  result.tracked = trajectory.size();
  result.lost = system.NumLost();
  result.keyframes = system.NumKeyFrames();
  result.map_points = system.NumMapPoints();
  result.wall_seconds = run.wall_seconds;

  Trajectory gt;
  for (const FrameData& f : run.ground_truth_frames) {
    if (f.world_from_cam_gt) gt.push_back({f.timestamp, *f.world_from_cam_gt});
  }
  if (gt.empty()) {
    result.note = "dataset has no ground truth";
  } else if (trajectory.size() < 3) {
    result.note = "fewer than 3 tracked frames";
  } else {
    try {
      EvalOptions eval;
      eval.alignment = Alignment::kSe3;
      result.ate_se3_m = EvaluateTrajectories(gt, trajectory, eval).ape.rmse;
      eval.alignment = Alignment::kSim3;
      const EvalResult sim3 = EvaluateTrajectories(gt, trajectory, eval);
      result.ate_sim3_m = sim3.ape.rmse;
      result.sim3_scale = sim3.gt_from_est.scale;
    } catch (const std::exception& e) {
      result.note = std::string("ATE not computed: ") + e.what();
    }
  }

  fs::create_directories(out_dir);
  WriteTumTrajectory(out_dir / "trajectory.tum", trajectory);
  WriteKittiTrajectory(out_dir / "trajectory.kitti", trajectory);
  WriteTumTrajectory(out_dir / "keyframes.tum", system.KeyFrameTrajectory());
  nlohmann::json summary = result.ToJson();
  summary["dataset"] = sequence.Kind() + ":" + sequence.Path().string();
  summary["depth"] = depth != nullptr ? depth->Name() : "none";
  summary["detector"] = detector != nullptr ? detector->Name() : "none";
  summary["seed"] = system_options.filter.seed;
  summary["per_frame"] = std::move(per_frame);
  WriteTextFileAtomic(out_dir / "summary.json", summary.dump(2) + "\n");
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
  os << "| variant | enh | dyn | dist | ATE se3 (m) | ATE sim3 (m) | tracked | keyframes | "
        "removed enh | removed dyn (small/st1/st2/vote) | removed distant (of >Z_th) |";
  if (truth) os << " moving removed | static person removed |";
  os << "\n|---|---|---|---|---|---|---|---|---|---|---|";
  if (truth) os << "---|---|";
  os << "\n";
  auto onoff = [](bool b) { return b ? "on" : "off"; };
  for (const VariantResult& r : results) {
    const FilterTotals& f = r.filters;
    os << "| " << r.variant.name << " | " << onoff(r.variant.enhancement) << " | "
       << onoff(r.variant.dynamic_removal) << " | " << onoff(r.variant.distant_filter) << " | "
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
      os << " " << pct(t.moving_removed, t.moving_keypoints) << " | "
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
