// `ademono run`: SLAM over a dataset sequence through the runner (runner/run.h), whose writer
// puts the run folder into --out (runner/run_writer.h); optionally per-frame feature images into
// --viz.
#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
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
#include "ademono/io/trajectory.h"
#include "ademono/live/live_server.h"
#include "ademono/report/report.h"
#include "ademono/runner/run.h"
#include "ademono/runner/run_writer.h"
#include "ademono/slam/system.h"
#include "command.h"
#include "run_options.h"
#include "stop_signals.h"

namespace fs = std::filesystem;

namespace ademono::cli {
namespace {

struct RunArgs : SequenceRunArgs {
  bool no_enhancement = false;
  bool no_dynamic_removal = false;
  bool no_distant_filter = false;
  std::string save_map, load_map;
  bool localize_only = false;
  bool overwrite = false;
  bool live_trajectory = false;
  bool realtime = false;
  double realtime_speed = 1.0;
  std::string live;  // [HOST:]PORT of the live view
  size_t live_wait_clients = 0;
  double live_linger = 0;
  double live_image_hz = 10;
  double live_map_hz = 2;
};

// SIGINT / SIGTERM: finish the current frame, then write the outputs of the frames done so far
// (summary.json "partial": true). SA_RESETHAND: a second signal ends the process at once, which
// the kill-safe writer (runner/run_writer.h) makes harmless.
std::atomic<bool> g_stop{false};
volatile std::sig_atomic_t g_stop_signal = 0;
extern "C" void OnStopSignal(int signo) {
  g_stop_signal = signo;
  g_stop.store(true);
}

// --live-trajectory: DIR/trajectory.live.tum gets one line per tracked frame (its pose when it was
// tracked, before later refinement), each fsynced, for a robot reading the run as it goes.
class LiveTrajectory {
 public:
  explicit LiveTrajectory(const fs::path& path) : path_(path) {
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0)
      ThrowInputError(path, std::string("cannot open for writing: ") + std::strerror(errno));
    Append(kTumHeader);
  }
  ~LiveTrajectory() { ::close(fd_); }
  LiveTrajectory(const LiveTrajectory&) = delete;
  LiveTrajectory& operator=(const LiveTrajectory&) = delete;
  void Add(double timestamp, const Rigid3d& cam_from_world) {
    Append(FormatTumLine({timestamp, cam_from_world.inverse()}));
  }

 private:
  void Append(const std::string& line) {
    // One write per line: a reader (or a kill) sees whole lines only, bar the very last one.
    if (::write(fd_, line.data(), line.size()) != static_cast<ssize_t>(line.size()) ||
        ::fdatasync(fd_) != 0) {
      ThrowInputError(path_, std::string("write failed: ") + std::strerror(errno));
    }
  }
  fs::path path_;
  int fd_ = -1;
};

// `run` writes into an empty or new folder, or replaces a run's outputs with --overwrite (as
// `synth` refuses a non-empty folder). A killed run's staging folder does not count.
void CheckOutputFolder(const fs::path& out, bool overwrite) {
  std::error_code ec;
  if (!fs::exists(out, ec)) return;
  if (!fs::is_directory(out, ec)) ThrowInputError(out, "exists and is not a directory");
  if (overwrite) return;
  for (const auto& entry : fs::directory_iterator(out, ec)) {
    if (!IsStagingEntry(entry.path()))
      ThrowInputError(out, "exists and is not empty (--overwrite replaces its run outputs)");
  }
}

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
  if (args.live.empty() && (args.live_wait_clients > 0 || args.live_linger > 0))
    throw InputError("--live-wait-clients and --live-linger need --live [HOST:]PORT");
  std::optional<live::LiveOptions> live_options;
  if (!args.live.empty()) {
    live_options = live::ParseLiveAddress(args.live);
    live_options->image_hz = args.live_image_hz;
    live_options->map_hz = args.live_map_hz;
  }
  CheckOutputFolder(args.out, args.overwrite);
  std::optional<fs::path> camera_yaml;
  if (!args.camera.empty()) camera_yaml = args.camera;
  const std::unique_ptr<Sequence> sequence = OpenSequence(args.dataset, camera_yaml);

  // Config: --config or the dataset family's default.
  const fs::path config_path = ResolveConfigPath(args.config, *sequence, args.depth);
  const YAML::Node config = LoadConfig(config_path, args.set);
  SystemOptions options = SystemOptionsFromConfig(config, config_path, args.set);
  ApplyDepthSource(args.depth, options);
  ApplyDatasetCameraHeight(config, *sequence, options);
  const DetectorOptions detector_options = DetectorOptionsFromConfig(config, config_path);
  if (!args.seed.empty()) options.SetSeed(ParseSeed(args.seed));
  if (args.no_enhancement) options.filter.enable_enhancement = false;
  if (args.no_dynamic_removal) options.filter.enable_dynamic_removal = false;
  if (args.no_distant_filter) options.filter.enable_distant_filter = false;

  RunOptions run;
  run.system = options;
  run.dataset = args.dataset;
  run.config = config_path.string();
  run.detector = detector_options;
  if (!args.frames.empty())
    ParseFrames(args.frames, sequence->Size(), &run.pipeline.start, &run.pipeline.end);
  run.pipeline.overlap = !args.no_overlap;
  run.pipeline.prefetch_frames = args.prefetch_frames;
  run.load_map = args.load_map;
  run.localize_only = args.localize_only;
  run.save_map = args.save_map;
  const bool live_camera = sequence->Kind() == "camera";
  if (args.realtime || live_camera) {
    RealtimeOptions realtime;
    realtime.speed = args.realtime_speed;
    run.realtime = realtime;
  }

  DepthFactoryContext context;
  context.sequence = sequence.get();
  context.seed = options.filter.seed;
  std::unique_ptr<DepthProvider> depth = MakeDepthProvider(args.depth, context);
  std::unique_ptr<Detector> detector = MakeDetector(args.detector, detector_options);

  const fs::path viz = args.viz;
  // A live camera has no end: progress then shows frames without a total.
  const size_t total =
      live_camera ? 0 : std::min(run.pipeline.end, sequence->Size()) - run.pipeline.start;
  const bool tty = isatty(STDERR_FILENO) != 0;
  const auto start_time = std::chrono::steady_clock::now();
  size_t done = 0;
  int lost_so_far = 0;
  if (!viz.empty()) fs::create_directories(viz);
  std::optional<LiveTrajectory> live;
  if (args.live_trajectory) {
    fs::create_directories(args.out);
    live.emplace(fs::path(args.out) / "trajectory.live.tum");
  }
  // The live view (docs/live.md) serves from its own thread; the run only hands it copies.
  std::unique_ptr<live::LiveServer> live_server;
  if (live_options) {
    live_server = std::make_unique<live::LiveServer>(*live_options);
    run.observer = live_server.get();
    std::fprintf(stderr, "ademono run: live view at %s (Foxglove / Lichtblick: ws://%s)\n",
                 live_server->Url().c_str(),
                 live_server->Url().substr(7, live_server->Url().size() - 8).c_str());
  }
  run.on_frame = [&](const FrameData& frame, const std::vector<Detection>& detections,
                     const TrackResult& r) {
    ++done;
    if (!r.tracked && r.state != TrackingState::kNotInitialized) ++lost_so_far;
    if (!viz.empty()) WriteViz(viz, frame, detections, r, options.filter);
    if (live && r.tracked && r.cam_from_world) live->Add(frame.timestamp, *r.cam_from_world);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
    const double fps = seconds > 0 ? done / seconds : 0.0;
    if (total == 0) {
      if (done % 100 == 0) {
        std::fprintf(stderr, "ademono run: %zu frames, %.1f fps, lost %d\n", done, fps,
                     lost_so_far);
      }
    } else if (tty) {
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
  g_stop.store(false);
  run.pipeline.stop = &g_stop;
  std::optional<StopSignals> signals;
  signals.emplace(OnStopSignal, SA_RESETHAND);
  if (live_server && args.live_wait_clients > 0) {
    std::fprintf(stderr, "ademono run: waiting for %zu live client(s)\n", args.live_wait_clients);
    live_server->WaitForClients(args.live_wait_clients, &g_stop);
  }
  RunReport report = RunSequence(*sequence, depth.get(), detector.get(), run);
  signals.reset();  // from here a signal ends the process; the writer below is kill-safe
  const int stop_exit = report.partial ? 128 + static_cast<int>(g_stop_signal) : 0;
  if (report.partial) {
    if (tty) std::fprintf(stderr, "\n");
    std::fprintf(stderr, "ademono run: %s after %zu/%zu frames; writing partial outputs\n",
                 g_stop_signal == SIGTERM ? "SIGTERM" : "SIGINT", report.frames, total);
    if (report.trajectory.empty()) {
      std::fprintf(stderr, "ademono run: no frame tracked yet, nothing written\n");
      return stop_exit;
    }
  }
  if (report.trajectory.empty() && !args.load_map.empty()) {
    throw InputError(args.dataset + ": no frame could be relocalised in the map " + args.load_map);
  }
  if (report.trajectory.empty()) {
    throw InputError(
        args.dataset +
        ": no frame could be tracked (the map never initialised: too little valid depth?)");
  }
  if (report.realtime) {
    std::fprintf(stderr, "ademono run: real time: %zu frames captured, %zu dropped\n",
                 report.realtime_stats.captured, report.realtime_stats.dropped);
  }
  if (sequence->HasGroundTruth() && !report.accuracy)
    spdlog::warn("accuracy not computed: {}", report.accuracy_note);
  // Drops and skips up to the end of the run (the final messages are queued by now).
  if (live_server) report.live = live_server->Stats();
  RemoveStaleStaging(args.out);
  WriteRunOutputs(report, args.out);
  WriteRunReport(args.out, ReportOptions());  // report.html, from the files just written

  std::cout << "tracked " << report.Tracked() << "/" << report.frames << " frames (lost "
            << report.lost << "), " << report.keyframes << " keyframes, " << report.map_points
            << " map points; tracking median " << std::fixed << std::setprecision(1)
            << report.timing.at("tracking").median_ms << " ms/frame\n";
  if (report.accuracy) {
    // Without depth or a camera height the map's unit is its two-view start's: se3 then scores
    // that unit, not the trajectory's shape.
    const bool scale_free = report.depth == "none" && !report.options.depth.GroundScale();
    std::cout << "ATE se3 " << std::setprecision(4) << report.accuracy->ate_se3_rmse_m
              << " m, sim3 " << report.accuracy->ate_sim3_rmse_m << " m"
              << (scale_free ? " (no metric scale without depth: read sim3)" : "") << "\n";
  }
  if (report.Tracked() < report.frames) {
    std::cout << (report.frames - report.Tracked()) << " frames untracked (no pose written)\n";
  }
  if (live_server) {
    // The outputs are written; the viewers get the final state, then the server closes.
    std::cout << std::flush;
    live_server->Linger(args.live_linger);
    live_server->Stop();
  }
  return stop_exit;
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
      app.add_option("--save-map", args->save_map,
                     "write the final map to FILE (docs/maps.md; atomic, versioned, checksummed)");
      app.add_option("--load-map", args->load_map,
                     "start from the map in FILE: relocalise in it, then extend it");
      app.add_flag("--localize-only", args->localize_only,
                   "with --load-map: track against the loaded map without ever changing it");
      app.add_flag("--overwrite", args->overwrite,
                   "replace the run outputs of a folder that already holds files");
      app.add_flag("--realtime", args->realtime,
                   "take frames at the source's rate, dropping those tracking has no time for "
                   "(always on for camera:N)");
      app.add_option("--realtime-speed", args->realtime_speed,
                     "with --realtime, replay a file this many times faster than recorded")
          ->check(CLI::Range(0.01, 1000.0));
      app.add_flag("--live-trajectory", args->live_trajectory,
                   "also append each tracked frame's pose to OUT/trajectory.live.tum as it is "
                   "tracked (one fsynced line per frame)");
      app.add_option("--live", args->live,
                     "serve the run live on [HOST:]PORT (default host 127.0.0.1): the Foxglove "
                     "WebSocket protocol for Foxglove / Lichtblick and a page at http://HOST:PORT/ "
                     "(docs/live.md; port 0: any free port, printed)");
      app.add_option("--live-wait-clients", args->live_wait_clients,
                     "with --live, start only once N clients have subscribed (to every channel, "
                     "or 1 s after their first subscription)");
      app.add_option("--live-linger", args->live_linger,
                     "with --live, keep serving up to SECONDS after the run, until every client "
                     "has left (default 0: until the final messages are sent, at most 5 s)")
          ->check(CLI::Range(0.0, 86400.0));
      app.add_option("--live-image-hz", args->live_image_hz,
                     "with --live, send the camera image at most this often")
          ->check(CLI::Range(0.1, 1000.0))
          ->capture_default_str();
      app.add_option("--live-map-hz", args->live_map_hz,
                     "with --live, send the map (cloud, trajectory, scene) at most this often "
                     "while it changes (the final map always)")
          ->check(CLI::Range(0.1, 1000.0))
          ->capture_default_str();
      return [args] { return Run(*args); };
    });

}  // namespace
}  // namespace ademono::cli
