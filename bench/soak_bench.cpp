// Soak: a long synthetic office run straight from synth's renderer into slam::System (no images
// on disk), the camera going back and forth along the office's path so the map saturates
// (issue 16 part 3). Reports, per 1000-frame window, the tracking fps (wall time in TrackFrame,
// and frames per CPU second of the whole process, which other load on the machine cannot lower),
// the resident memory and the map's size; and peak RSS at 1k, 5k and 10k frames as benchmark
// counters. Peak RSS is per process: run one variant per process (tools/soak.sh does).
//
//   build/release/bench/bench_soak                      # 10,000 frames, three variants
//   ADEMONO_SOAK_FRAMES=3000 build/release/bench/bench_soak --benchmark_filter=Soak/Plain/
//
// Variants: Plain (exact depth, no detections), Detections (the persons' ground-truth boxes, as
// `--detector cache:` of a synth folder), NetworkDepth (simulated network depth: scale bias,
// per-frame jitter, edge errors; depth treated as a prior with scale correction, as with
// `--depth model:`).
#include <benchmark/benchmark.h>
#include <malloc.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

#include "ademono/depth/simulated_depth.h"
#include "ademono/slam/system.h"
#include "ademono/synth/generator.h"
#include "ademono/synth/scenes.h"
#include "slam/simulated_network.h"  // tests/: the tests' simulated network

namespace {

using namespace ademono;

enum Variant { kPlain = 0, kDetections = 1, kNetworkDepth = 2 };
const char* const kVariantNames[] = {"plain", "detections", "network_depth"};

// Report window (frames), ADEMONO_SOAK_WINDOW; 1000 by default. Shorter windows show how the map
// grows early on (the 1k/5k/10k counters are taken whatever the window).
size_t SoakWindow() {
  const char* env = std::getenv("ADEMONO_SOAK_WINDOW");
  const size_t w = env != nullptr ? std::strtoul(env, nullptr, 10) : 1000;
  return w > 0 ? w : 1000;
}

size_t SoakFrames() {
  const char* env = std::getenv("ADEMONO_SOAK_FRAMES");
  return env != nullptr ? std::strtoul(env, nullptr, 10) : 10000;
}

double PeakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // KB on Linux
}

// Bytes malloc has handed out and not had back: what the program holds, without the allocator's
// free but unreturned pages (RSS minus this, minus the code, is fragmentation and arenas).
double HeapInUseMb() {
  const struct mallinfo2 info = mallinfo2();
  return static_cast<double>(info.uordblks + info.hblkhd) / (1024.0 * 1024.0);
}

// CPU seconds of every thread of the process (the run's own threads too).
double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double CurrentRssMb() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * static_cast<double>(::sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

// ADEMONO_SOAK_SET="section.key=value;section.key=value": overrides on top of the variant's
// configuration (as `ademono run --set`), to compare settings on the soak.
SystemOptions Options(Variant variant) {
  SystemOptions options;
  YAML::Node config(YAML::NodeType::Map);
  std::string path = "ADEMONO_SOAK_SET";
  if (variant == kNetworkDepth) {
    // What `ademono run --depth model:...` picks indoors: depth as a prior with scale correction.
    path = std::string(ADEMONO_SOURCE_DIR) + "/configs/network_indoor.yaml";
    config = YAML::LoadFile(path);
  }
  bool overridden = false;
  if (const char* env = std::getenv("ADEMONO_SOAK_SET")) {
    std::string items = env;
    size_t start = 0;
    while (start < items.size()) {
      size_t end = items.find(';', start);
      if (end == std::string::npos) end = items.size();
      const std::string item = items.substr(start, end - start);
      start = end + 1;
      const size_t dot = item.find('.'), eq = item.find('=');
      if (dot == std::string::npos || eq == std::string::npos || eq < dot) {
        std::fprintf(stderr, "ADEMONO_SOAK_SET: '%s' is not section.key=value\n", item.c_str());
        std::exit(2);
      }
      config[item.substr(0, dot)][item.substr(dot + 1, eq - dot - 1)] =
          YAML::Load(item.substr(eq + 1));
      std::fprintf(stderr, "set %s\n", item.c_str());
      overridden = true;
    }
  }
  if (variant == kNetworkDepth || overridden) options = SystemOptions::FromYaml(config, path);
  options.orb.num_features = 1000;
  options.filter.enable_dynamic_removal = variant == kDetections;
  return options;
}

void BM_Soak(benchmark::State& state) {
  const auto variant = static_cast<Variant>(state.range(0));
  // ADEMONO_SOAK_LOG=debug: the library's debug log (keyframe decisions, local mapping) on stderr.
  if (const char* level = std::getenv("ADEMONO_SOAK_LOG"))
    spdlog::set_level(spdlog::level::from_str(level));
  const size_t frames = SoakFrames();
  const size_t report_window = SoakWindow();
  const size_t period = 300;  // 10 s of the office path at 30 fps
  synth::SceneOptions scene_options;
  scene_options.scene = "office";
  scene_options.frames = period;
  scene_options.seed = 5;
  scene_options.persons = variant == kDetections ? 2 : 1;
  scene_options.width = 320;
  scene_options.height = 240;
  const synth::Scene scene = synth::BuildScene(scene_options);
  synth::GeneratorOptions generator;
  generator.scene = scene_options;
  const SimulatedDepthProvider network(testing_util::FastDepthLikeNetwork(60, 3), nullptr);

  std::fprintf(stderr, "soak %s: %zu frames (back and forth over %zu), 320x240\n",
               kVariantNames[variant], frames, period);
  std::fprintf(stderr, "%8s %8s %8s %8s %10s %10s %10s %9s %10s\n", "frames", "fps", "cpu_fps",
               "lost", "rss_mb", "peak_mb", "heap_mb", "keyframes", "map_points");
  for (auto _ : state) {
    System system(scene.camera, Options(variant));
    double tracking_seconds = 0;
    // The whole process's CPU over a window (rendering and the mapping thread included): an fps
    // that other load on the machine cannot lower, for the trend over the run.
    double window_cpu_start = ProcessCpuSeconds();
    int lost_in_window = 0;
    for (size_t k = 0; k < frames; ++k) {
      const size_t source = testing_util::BackAndForthFrame(k, period);
      const synth::RenderedFrame rendered = synth::RenderSceneFrame(scene, source, generator);
      FrameData frame;
      frame.index = k;
      frame.timestamp = k / scene.fps;  // time keeps running while the path repeats
      frame.name = std::to_string(k);
      frame.image = rendered.image;
      const cv::Mat depth =
          variant == kNetworkDepth ? network.Degrade(rendered.depth, k) : rendered.depth;
      std::vector<Detection> detections;
      if (variant == kDetections)
        detections = synth::BoxesFromObjectIds(scene, rendered.object_id, generator.min_box_pixels);
      const auto start = std::chrono::steady_clock::now();
      const TrackResult r = system.TrackFrame(frame, depth, detections);
      tracking_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      lost_in_window += r.tracked ? 0 : 1;
      if ((k + 1) % report_window == 0 || k + 1 == frames) {
        const size_t window = (k % report_window) + 1;
        const double peak = PeakRssMb();
        const double heap = HeapInUseMb();
        const double window_cpu = ProcessCpuSeconds() - window_cpu_start;
        std::fprintf(stderr, "%8zu %8.1f %8.1f %8d %10.1f %10.1f %10.1f %9zu %10zu\n", k + 1,
                     window / tracking_seconds, window / window_cpu, lost_in_window,
                     CurrentRssMb(), peak, heap,
                     system.NumKeyFrames(), system.NumMapPoints());
        const size_t done = k + 1;
        if (done == 1000) state.counters["heap_1k_mb"] = heap;
        if (done == 10000) state.counters["heap_10k_mb"] = heap;
        if (done == 1000) state.counters["peak_rss_1k_mb"] = peak;
        if (done == 5000) state.counters["peak_rss_5k_mb"] = peak;
        if (done == 10000) state.counters["peak_rss_10k_mb"] = peak;
        if (done == report_window) state.counters["fps_first_window"] = window / tracking_seconds;
        state.counters["fps_last_window"] = window / tracking_seconds;
        if (done == report_window) state.counters["cpu_fps_first_window"] = window / window_cpu;
        state.counters["cpu_fps_last_window"] = window / window_cpu;
        tracking_seconds = 0;
        window_cpu_start = ProcessCpuSeconds();
        lost_in_window = 0;
      }
    }
    system.Shutdown();
    state.counters["keyframes"] = static_cast<double>(system.NumKeyFrames());
    state.counters["map_points"] = static_cast<double>(system.NumMapPoints());
    state.counters["tracked"] = static_cast<double>(system.FrameTrajectory().size());
  }
}

BENCHMARK(BM_Soak)->Name("Soak/Plain")->Arg(kPlain)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_Soak)
    ->Name("Soak/Detections")
    ->Arg(kDetections)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK(BM_Soak)
    ->Name("Soak/NetworkDepth")
    ->Arg(kNetworkDepth)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
