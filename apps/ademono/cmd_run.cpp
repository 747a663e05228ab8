// `ademono run`: SLAM over a dataset sequence through the runner (runner/run.h), whose writer
// puts the run folder into --out (runner/run_writer.h); optionally per-frame feature images into
// --viz.
#include <spdlog/spdlog.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <string>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/depth/depth_factory.h"
#include "ademono/detect/detector_factory.h"
#include "ademono/filter/visualize.h"
#include "ademono/io/sequence.h"
#include "ademono/report/report.h"
#include "ademono/runner/run.h"
#include "ademono/runner/run_writer.h"
#include "ademono/slam/system.h"
#include "command.h"
#include "run_options.h"

namespace fs = std::filesystem;

namespace ademono::cli {
namespace {

struct RunArgs : SequenceRunArgs {
  bool no_enhancement = false;
  bool no_dynamic_removal = false;
  bool no_distant_filter = false;
  bool threaded = false;
  std::string save_map, load_map;
  bool localize_only = false;
};

// The filter's view of the frame (boxes as the filter grew them, keypoints by label, legend).
void WriteViz(const fs::path& dir, const FrameData& frame, const std::vector<Detection>& detections,
              const TrackResult& r, const FilterOptions& filter) {
  std::ostringstream name;
  name << "frame-" << std::setw(6) << std::setfill('0') << frame.index << ".jpg";
  WriteImageAtomic(dir / name.str(),
                   DrawFilterResult(frame.image, r.keypoints, r.labels, detections, filter));
}

int Run(const RunArgs& args) {
  if (args.out.empty()) throw InputError("--out is required");
  if (args.localize_only && args.load_map.empty())
    throw InputError("--localize-only needs --load-map FILE");
  std::optional<fs::path> camera_yaml;
  if (!args.camera.empty()) camera_yaml = args.camera;
  const std::unique_ptr<Sequence> sequence = OpenSequence(args.dataset, camera_yaml);

  // Config: --config or the dataset family's default.
  const fs::path config_path = ResolveConfigPath(args.config, *sequence, args.depth);
  const YAML::Node config = LoadConfig(config_path, args.set);
  SystemOptions options = SystemOptions::FromYaml(config, config_path);
  ApplyDepthSource(args.depth, options);
  const DetectorOptions detector_options = DetectorOptionsFromConfig(config, config_path);
  if (!args.seed.empty()) options.filter.seed = ParseSeed(args.seed);
  if (args.no_enhancement) options.filter.enable_enhancement = false;
  if (args.no_dynamic_removal) options.filter.enable_dynamic_removal = false;
  if (args.no_distant_filter) options.filter.enable_distant_filter = false;
  if (args.threaded) options.mapping.deterministic = false;

  RunOptions run;
  run.system = options;
  run.dataset = args.dataset;
  run.config = config_path.string();
  run.detector = detector_options;
  if (!args.frames.empty())
    ParseFrames(args.frames, sequence->Size(), &run.pipeline.start, &run.pipeline.end);
  run.pipeline.overlap = !args.no_overlap;
  run.load_map = args.load_map;
  run.localize_only = args.localize_only;
  run.save_map = args.save_map;

  DepthFactoryContext context;
  context.sequence = sequence.get();
  context.seed = options.filter.seed;
  std::unique_ptr<DepthProvider> depth = MakeDepthProvider(args.depth, context);
  std::unique_ptr<Detector> detector = MakeDetector(args.detector, detector_options);

  const fs::path viz = args.viz;
  const size_t total = std::min(run.pipeline.end, sequence->Size()) - run.pipeline.start;
  const bool tty = isatty(STDERR_FILENO) != 0;
  const auto start_time = std::chrono::steady_clock::now();
  size_t done = 0;
  int lost_so_far = 0;
  if (!viz.empty()) fs::create_directories(viz);
  run.on_frame = [&](const FrameData& frame, const std::vector<Detection>& detections,
                     const TrackResult& r) {
    ++done;
    if (!r.tracked && r.state != TrackingState::kNotInitialized) ++lost_so_far;
    if (!viz.empty()) WriteViz(viz, frame, detections, r, options.filter);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
    const double fps = seconds > 0 ? done / seconds : 0.0;
    if (tty) {
      const int width = 30;
      const int filled = static_cast<int>(width * done / std::max<size_t>(1, total));
      std::fprintf(stderr, "\r[%s%s] %zu/%zu  %.1f fps  lost %d", std::string(filled, '=').c_str(),
                   std::string(width - filled, ' ').c_str(), done, total, fps, lost_so_far);
      if (done == total) std::fprintf(stderr, "\n");
    } else if (done % 100 == 0 || done == total) {
      std::fprintf(stderr, "ademono run: %zu/%zu frames, %.1f fps, lost %d\n", done, total, fps,
                   lost_so_far);
    }
  };
  const RunReport report = RunSequence(*sequence, depth.get(), detector.get(), run);
  if (report.trajectory.empty() && !args.load_map.empty()) {
    throw InputError(args.dataset + ": no frame could be relocalised in the map " + args.load_map);
  }
  if (report.trajectory.empty()) {
    throw InputError(
        args.dataset +
        ": no frame could be tracked (the map never initialised: too little valid depth?)");
  }
  if (sequence->HasGroundTruth() && !report.accuracy)
    spdlog::warn("accuracy not computed: {}", report.accuracy_note);
  WriteRunOutputs(report, args.out);
  WriteRunReport(args.out, ReportOptions());  // report.html, from the files just written

  std::cout << "tracked " << report.Tracked() << "/" << report.frames << " frames (lost "
            << report.lost << "), " << report.keyframes << " keyframes, " << report.map_points
            << " map points; tracking median " << std::fixed << std::setprecision(1)
            << report.timing.at("tracking").median_ms << " ms/frame\n";
  if (report.accuracy) {
    std::cout << "ATE se3 " << std::setprecision(4) << report.accuracy->ate_se3_rmse_m
              << " m, sim3 " << report.accuracy->ate_sim3_rmse_m << " m\n";
  }
  if (report.Tracked() < report.frames) {
    std::cout << (report.frames - report.Tracked()) << " frames untracked (no pose written)\n";
  }
  return 0;
}

const bool kRegistered = RegisterCommand(
    "run", "Run SLAM over a dataset sequence and write trajectory, keyframes, map and summary",
    [](CLI::App& app) -> Runner {
      auto args = std::make_shared<RunArgs>();
      AddSequenceRunOptions(app, *args);
      app.add_flag("--no-enhancement", args->no_enhancement,
                   "disable depth-weighted feature enhancement");
      app.add_flag("--no-dynamic-removal", args->no_dynamic_removal,
                   "disable dynamic interference removal");
      app.add_flag("--no-distant-filter", args->no_distant_filter,
                   "disable distant-point filtering");
      app.add_flag(
          "--threaded", args->threaded,
          "local mapping in its own thread (faster wall time, not reproducible run to run)");
      app.add_option("--save-map", args->save_map,
                     "write the final map to FILE (docs/maps.md; atomic, versioned, checksummed)");
      app.add_option("--load-map", args->load_map,
                     "start from the map in FILE: relocalise in it, then extend it");
      app.add_flag("--localize-only", args->localize_only,
                   "with --load-map: track against the loaded map without ever changing it");
      return [args] { return Run(*args); };
    });

}  // namespace
}  // namespace ademono::cli
