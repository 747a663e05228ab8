// `ademono ablate`: the filter ablation (full / no_dynamic / no_distant / no_dynamic_no_distant /
// no_enhancement) over one sequence; each variant's run outputs go into --out/<variant>/, the
// comparison into --out/ablation.md and --out/ablation.json. The work is in runner/ablation.h.
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/depth/depth_factory.h"
#include "ademono/detect/detector_factory.h"
#include "ademono/filter/visualize.h"
#include "ademono/io/sequence.h"
#include "ademono/report/report.h"
#include "ademono/runner/ablation.h"
#include "command.h"
#include "run_options.h"

namespace fs = std::filesystem;

namespace ademono::cli {
namespace {

struct AblateArgs : SequenceRunArgs {
  std::string variants;  // comma-separated subset, empty: all five
};

std::vector<AblationVariant> SelectVariants(const std::string& list) {
  const auto& all = AllAblationVariants();
  if (list.empty()) return DefaultAblationVariants();
  std::vector<AblationVariant> chosen;
  std::stringstream ss(list);
  std::string name;
  while (std::getline(ss, name, ',')) {
    auto it = std::find_if(all.begin(), all.end(),
                           [&](const AblationVariant& v) { return v.name == name; });
    if (it == all.end()) {
      std::string names;
      for (const auto& v : all) names += (names.empty() ? "" : ", ") + v.name;
      throw InputError("--variants: unknown variant '" + name + "' (known: " + names + ")");
    }
    chosen.push_back(*it);
  }
  if (chosen.empty()) throw InputError("--variants: empty list");
  return chosen;
}

int Ablate(const AblateArgs& args) {
  const std::vector<AblationVariant> variants = SelectVariants(args.variants);
  std::optional<fs::path> camera_yaml;
  if (!args.camera.empty()) camera_yaml = args.camera;
  const std::unique_ptr<Sequence> sequence = OpenSequence(args.dataset, camera_yaml);

  const fs::path config_path = ResolveConfigPath(args.config, *sequence, args.depth);
  const YAML::Node config = LoadConfig(config_path, args.set);
  AblationOptions options;
  options.system = SystemOptionsFromConfig(config, config_path, args.set);
  ApplyDepthSource(args.depth, options.system);
  ApplyDatasetCameraHeight(config, *sequence, options.system);
  options.variants = variants;
  options.dataset = args.dataset;
  options.config = config_path.string();
  const DetectorOptions detector_options = DetectorOptionsFromConfig(config, config_path);
  options.detector = detector_options;
  if (!args.seed.empty()) options.system.SetSeed(ParseSeed(args.seed));
  if (!args.frames.empty())
    ParseFrames(args.frames, sequence->Size(), &options.pipeline.start, &options.pipeline.end);
  options.pipeline.overlap = !args.no_overlap;
  options.pipeline.prefetch_frames = args.prefetch_frames;

  DepthFactoryContext context;
  context.sequence = sequence.get();
  context.seed = options.system.filter.seed;
  std::unique_ptr<DepthProvider> depth = MakeDepthProvider(args.depth, context);
  std::unique_ptr<Detector> detector = MakeDetector(args.detector, detector_options);

  const size_t total = std::min(options.pipeline.end, sequence->Size()) - options.pipeline.start;
  size_t done = 0;
  options.on_frame = [&](const AblationVariant& v, const FrameData& frame,
                         const std::vector<Detection>& detections, const TrackResult& r) {
    ++done;
    if (!args.viz.empty()) {
      FilterOptions filter = options.system.filter;
      filter.enable_dynamic_removal = v.dynamic_removal;
      std::ostringstream name;
      name << "frame-" << std::setw(6) << std::setfill('0') << frame.index << ".jpg";
      WriteImageAtomic(fs::path(args.viz) / v.name / name.str(),
                       DrawFilterResult(frame.image, r.keypoints, r.labels, detections, filter));
    }
    if (done % total == 0) {
      std::fprintf(stderr, "ademono ablate: variant %s done (%zu frames)\n", v.name.c_str(), total);
    }
  };
  if (!args.viz.empty()) {
    for (const auto& v : variants) fs::create_directories(fs::path(args.viz) / v.name);
  }
  const std::vector<VariantResult> results =
      RunAblation(*sequence, depth.get(), detector.get(), options, args.out);
  std::vector<fs::path> run_dirs;
  std::vector<std::string> names;
  for (const VariantResult& r : results) {
    run_dirs.push_back(fs::path(args.out) / r.variant.name);
    names.push_back(r.variant.name);
  }
  WriteComparisonReport(run_dirs, names, ReportOptions(), fs::path(args.out) / "report.html");
  std::cout << AblationMarkdown(results);
  return 0;
}

const bool kRegistered = RegisterCommand(
    "ablate",
    "Run the filter ablation (5 variants) over a sequence: ATE, tracking, filter counts table",
    [](CLI::App& app) -> Runner {
      auto args = std::make_shared<AblateArgs>();
      AddSequenceRunOptions(app, *args);
      app.add_option("--variants", args->variants,
                     "comma-separated subset of full,no_dynamic,no_distant,"
                     "no_dynamic_no_distant,no_enhancement,boxes_only,geometry_only (default: "
                     "the first five)");
      return [args] { return Ablate(*args); };
    });

}  // namespace
}  // namespace ademono::cli
