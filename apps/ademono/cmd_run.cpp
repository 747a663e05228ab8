// `ademono run`: SLAM over a dataset sequence. Writes trajectory.tum, trajectory.kitti,
// keyframes.tum, map.ply and summary.json into --out (each atomically), optionally per-frame
// feature images into --viz.
#include <spdlog/spdlog.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <string>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/depth/depth_factory.h"
#include "ademono/detect/detector_factory.h"
#include "ademono/eval/trajectory_eval.h"
#include "ademono/filter/visualize.h"
#include "ademono/io/sequence.h"
#include "ademono/io/trajectory.h"
#include "ademono/slam/ablation.h"
#include "ademono/slam/pipeline.h"
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
};

void WritePly(const fs::path& path, const std::vector<System::ColoredPoint>& cloud) {
  WriteFileAtomic(path, [&](std::ostream& os) {
    os << "ply\nformat ascii 1.0\nelement vertex " << cloud.size()
       << "\nproperty float x\nproperty float y\nproperty float z\n"
          "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
    char line[128];
    for (const auto& p : cloud) {
      std::snprintf(line, sizeof(line), "%.6f %.6f %.6f %d %d %d\n", p.position.x(), p.position.y(),
                    p.position.z(), p.bgr[2], p.bgr[1], p.bgr[0]);
      os << line;
    }
  });
}

// The filter's view of the frame (boxes as the filter grew them, keypoints by label, legend).
void WriteViz(const fs::path& dir, const FrameData& frame, const std::vector<Detection>& detections,
              const TrackResult& r, const FilterOptions& filter) {
  std::ostringstream name;
  name << "frame-" << std::setw(6) << std::setfill('0') << frame.index << ".jpg";
  WriteImageAtomic(dir / name.str(),
                   DrawFilterResult(frame.image, r.keypoints, r.labels, detections, filter));
}

nlohmann::json TimingJson(const std::vector<double>& values) {
  return {{"median_ms", Percentile(values, 0.5)}, {"p95_ms", Percentile(values, 0.95)}};
}

// ATE (se3 and sim3 alignment) and RPE over one second of frames against the dataset's ground
// truth, with the evaluation module (the same numbers `ademono eval` prints).
nlohmann::json AccuracyJson(const std::vector<FrameData>& frames, const Trajectory& estimate) {
  Trajectory gt;
  for (const FrameData& f : frames) {
    if (f.world_from_cam_gt) gt.push_back({f.timestamp, *f.world_from_cam_gt});
  }
  if (gt.size() < 3 || estimate.size() < 3) return nullptr;
  nlohmann::json json;
  try {
    EvalOptions options;
    options.alignment = Alignment::kSe3;
    const EvalResult se3 = EvaluateTrajectories(gt, estimate, options);
    options.alignment = Alignment::kSim3;
    const EvalResult sim3 = EvaluateTrajectories(gt, estimate, options);
    options.alignment = Alignment::kSe3;
    options.rpe_delta = 30;
    const EvalResult rpe = EvaluateTrajectories(gt, estimate, options);
    json["matched_poses"] = se3.matched_poses;
    json["ate_se3_rmse_m"] = se3.ape.rmse;
    json["ate_sim3_rmse_m"] = sim3.ape.rmse;
    json["sim3_scale"] = sim3.gt_from_est.scale;
    json["rpe_30_frames_trans_rmse_m"] = rpe.rpe_trans.rmse;
    json["rpe_30_frames_rot_rmse_deg"] = rpe.rpe_rot_deg.rmse;
  } catch (const std::exception& e) {
    spdlog::warn("accuracy not computed: {}", e.what());
    return nullptr;
  }
  return json;
}

int Run(const RunArgs& args) {
  if (args.out.empty()) throw InputError("--out is required");
  std::optional<fs::path> camera_yaml;
  if (!args.camera.empty()) camera_yaml = args.camera;
  const std::unique_ptr<Sequence> sequence = OpenSequence(args.dataset, camera_yaml);

  // Config: --config or the dataset family's default.
  const fs::path config_path = ResolveConfigPath(args.config, *sequence, args.depth);
  const YAML::Node config = LoadConfig(config_path);
  SystemOptions options = SystemOptions::FromYaml(config, config_path);
  ApplyDepthSource(args.depth, options);
  const DetectorOptions detector_options = DetectorOptionsFromConfig(config, config_path);
  if (!args.seed.empty()) options.filter.seed = ParseSeed(args.seed);
  if (args.no_enhancement) options.filter.enable_enhancement = false;
  if (args.no_dynamic_removal) options.filter.enable_dynamic_removal = false;
  if (args.no_distant_filter) options.filter.enable_distant_filter = false;
  if (args.threaded) options.mapping.deterministic = false;

  PipelineOptions pipeline;
  if (!args.frames.empty())
    ParseFrames(args.frames, sequence->Size(), &pipeline.start, &pipeline.end);
  pipeline.overlap = !args.no_overlap;

  DepthFactoryContext context;
  context.sequence = sequence.get();
  context.seed = options.filter.seed;
  std::unique_ptr<DepthProvider> depth = MakeDepthProvider(args.depth, context);
  std::unique_ptr<Detector> detector = MakeDetector(args.detector, detector_options);

  const fs::path out(args.out);
  const fs::path viz = args.viz;
  System system(sequence->GetCamera(), options);
  const size_t total = std::min(pipeline.end, sequence->Size()) - pipeline.start;
  const bool tty = isatty(STDERR_FILENO) != 0;
  const auto start_time = std::chrono::steady_clock::now();
  size_t done = 0;
  int lost_so_far = 0;
  // Filter counts per frame and in total (slam/ablation.h FilterTotals).
  FilterTotals filter_totals;
  nlohmann::json filter_per_frame = nlohmann::json::array();
  if (!viz.empty()) fs::create_directories(viz);
  pipeline.on_frame = [&](const FrameData& frame, const cv::Mat&,
                          const std::vector<Detection>& detections, const TrackResult& r) {
    ++done;
    if (!r.tracked && r.state != TrackingState::kNotInitialized) ++lost_so_far;
    filter_totals.Add(r.filter_stats, r.num_keypoints);
    nlohmann::json counts = FilterStatsJson(r.filter_stats);
    counts["frame"] = frame.index;
    counts["keypoints"] = r.num_keypoints;
    filter_per_frame.push_back(std::move(counts));
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
  const PipelineResult result =
      RunPipeline(*sequence, depth.get(), detector.get(), system, pipeline);
  system.Shutdown();

  // Outputs.
  const Trajectory trajectory = system.FrameTrajectory();
  const Trajectory keyframes = system.KeyFrameTrajectory();
  if (trajectory.empty()) {
    throw InputError(
        args.dataset +
        ": no frame could be tracked (the map never initialised: too little valid depth?)");
  }
  WriteTumTrajectory(out / "trajectory.tum", trajectory);
  WriteKittiTrajectory(out / "trajectory.kitti", trajectory);
  WriteTumTrajectory(out / "keyframes.tum", keyframes);
  WritePly(out / "map.ply", system.MapPointCloud());

  std::vector<double> extraction, depth_ms, detection, filter, tracking, mapping;
  for (const FrameTiming& t : result.timings) {
    extraction.push_back(t.extraction_ms);
    depth_ms.push_back(t.depth_ms);
    detection.push_back(t.detection_ms);
    filter.push_back(t.filter_ms);
    tracking.push_back(t.tracking_ms);
    mapping.push_back(t.mapping_ms);
  }
  nlohmann::json summary;
  summary["dataset"] = args.dataset;
  summary["config"] = config_path.string();
  summary["depth"] = depth->Name();
  summary["detector"] = detector->Name();
  summary["seed"] = options.filter.seed;
  summary["deterministic"] = options.mapping.deterministic;
  summary["filters"] = {{"enhancement", options.filter.enable_enhancement},
                        {"dynamic_removal", options.filter.enable_dynamic_removal},
                        {"distant", options.filter.enable_distant_filter}};
  summary["filter_counts"] = filter_totals.ToJson();
  summary["filter_counts_per_frame"] = std::move(filter_per_frame);
  summary["frames"] = result.frames;
  summary["tracked"] = trajectory.size();
  summary["untracked"] = result.frames - trajectory.size();
  summary["lost"] = system.NumLost();
  summary["keyframes"] = system.NumKeyFrames();
  summary["map_points"] = system.NumMapPoints();
  summary["wall_seconds"] = result.wall_seconds;
  summary["fps"] = result.wall_seconds > 0 ? result.frames / result.wall_seconds : 0.0;
  summary["timing"] = {
      {"extraction", TimingJson(extraction)}, {"depth", TimingJson(depth_ms)},
      {"detection", TimingJson(detection)},   {"filter", TimingJson(filter)},
      {"tracking", TimingJson(tracking)},     {"local_mapping", TimingJson(mapping)}};
  if (sequence->HasGroundTruth()) {
    const nlohmann::json accuracy = AccuracyJson(result.ground_truth_frames, trajectory);
    if (!accuracy.is_null()) summary["accuracy"] = accuracy;
  }
  WriteTextFileAtomic(out / "summary.json", summary.dump(2) + "\n");

  std::cout << "tracked " << trajectory.size() << "/" << result.frames << " frames (lost "
            << system.NumLost() << "), " << system.NumKeyFrames() << " keyframes, "
            << system.NumMapPoints() << " map points; tracking median " << std::fixed
            << std::setprecision(1) << Percentile(tracking, 0.5) << " ms/frame\n";
  if (summary.contains("accuracy")) {
    std::cout << "ATE se3 " << std::setprecision(4)
              << summary["accuracy"]["ate_se3_rmse_m"].get<double>() << " m, sim3 "
              << summary["accuracy"]["ate_sim3_rmse_m"].get<double>() << " m\n";
  }
  if (trajectory.size() < result.frames) {
    std::cout << (result.frames - trajectory.size()) << " frames untracked (no pose written)\n";
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
      return [args] { return Run(*args); };
    });

}  // namespace
}  // namespace ademono::cli
