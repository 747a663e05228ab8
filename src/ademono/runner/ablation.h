#pragma once
// The paper's filter ablation: the same sequence, depth and detections run through the runner
// (runner/run.h) with the filters switched on and off, compared by ATE against the dataset's ground
// truth, tracking rate, keyframes and what each filter removed. Used by `ademono ablate`.
//
// On a synthetic sequence (`ademono synth`: masks/<name>.png of moving objects) the per-keypoint
// filter labels are also scored against the truth (runner/synthetic_truth.h).

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ademono/io/sequence.h"
#include "ademono/perception/depth_provider.h"
#include "ademono/perception/detection.h"
#include "ademono/runner/pipeline.h"
#include "ademono/runner/run.h"
#include "ademono/runner/synthetic_truth.h"
#include "ademono/slam/options.h"

namespace ademono {

struct AblationVariant {
  std::string name;  // directory name below the output directory
  bool enhancement = true;
  bool dynamic_removal = true;
  bool distant_filter = true;
  // The geometric test for movers without a box (tracking.static_test); the no_dynamic variants
  // switch it off with the box filter, so that they measure no dynamic handling at all.
  bool geometric_test = true;
  bool use_detector = true;  // false: the run sees no detections (geometry only)
  // The paper's small-box rule (every point in a small box dropped) instead of judging small boxes
  // like large ones (filter.judge_small_boxes).
  bool paper_small_boxes = false;
};
// full, no_dynamic, no_distant, no_dynamic_no_distant, no_enhancement.
const std::vector<AblationVariant>& DefaultAblationVariants();
// The defaults plus boxes_only (the detector's boxes through the paper's rule: small boxes dropped,
// the two-stage test in large ones, no geometric test) and geometry_only (no detections, the
// geometric test alone): with a real detector (`--detector model:...`) these compare what the boxes
// and the geometry each bring.
const std::vector<AblationVariant>& AllAblationVariants();

// The same variant as `ademono run` options: the config overrides ("section.key=value", for
// --set) that RunAblationVariant applies to the system options. Without the detector
// (use_detector false) the run also needs `--detector none`. Used by `ademono batch`, whose runs
// are separate `run` processes.
std::vector<std::string> AblationSetOverrides(const AblationVariant& variant);
// The variant named `name` of AllAblationVariants(); nullptr when there is none.
const AblationVariant* FindAblationVariant(const std::string& name);

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
  std::string dataset;  // label for each variant's summary.json (RunOptions::dataset)
  std::string config;   // config file of `system` (RunOptions::config)
  DetectorOptions detector;  // for each variant's config.resolved.yaml
  std::vector<AblationVariant> variants = DefaultAblationVariants();
  bool score_synthetic_truth = true;  // when the sequence has masks/
  // Called after each frame of each variant (e.g. progress, --viz).
  std::function<void(const AblationVariant&, const FrameData&, const std::vector<Detection>&,
                     const TrackResult&)>
      on_frame;
};

// Runs one variant and writes its run folder (runner/run_writer.h: the same outputs as
// `ademono run`) into `out_dir` (created). `depth` / `detector` are shared by the
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
