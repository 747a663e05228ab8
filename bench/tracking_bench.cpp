// Per-frame SLAM cost on 7-Scenes (640x480) with sensor depth, on one core.
//   BM_TrackingStep: pose tracking only (motion model / local map search, pose optimisation,
//                    keyframe decision), i.e. TrackResult::tracking_ms, manual time; arg 0:
//                    pose optimisation with Ceres, 1: the built-in Levenberg-Marquardt.
//   BM_FrameNoDepthNoDetection: everything System::TrackFrame does (ORB extraction, keypoint
//                    depth, filters, tracking, and local mapping in deterministic mode).
// Frames 0..kFrames-1 are loaded once; when they run out a fresh System starts again (untimed).
#include <benchmark/benchmark.h>
#include <yaml-cpp/yaml.h>

#include <memory>
#include <string>
#include <vector>

#include "ademono/depth/depth_factory.h"
#include "ademono/io/sequence.h"
#include "ademono/slam/system.h"

namespace {

constexpr size_t kFrames = 90;

struct Data {
  std::unique_ptr<ademono::Sequence> sequence;
  std::vector<ademono::FrameData> frames;
  std::vector<cv::Mat> depths;
};

const Data& LoadData() {
  static const Data data = [] {
    Data d;
    d.sequence =
        ademono::OpenSequence(std::string("7scenes:") + ADEMONO_SHARED_DIR + "/data/7scenes-seq-a");
    ademono::DepthFactoryContext context;
    context.sequence = d.sequence.get();
    auto provider = ademono::MakeDepthProvider("sensor", context);
    for (size_t i = 0; i < kFrames; ++i) {
      d.frames.push_back(d.sequence->Load(i));
      d.depths.push_back(provider->Depth(d.frames.back(), d.sequence->GetCamera()));
    }
    return d;
  }();
  return data;
}

// configs/7scenes.yaml, what `ademono run --dataset 7scenes:...` uses, with local mapping on the
// calling thread so that BM_FrameNoDepthNoDetection's time includes it.
ademono::SystemOptions BenchOptions() {
  const std::string path = std::string(ADEMONO_SOURCE_DIR) + "/configs/7scenes.yaml";
  ademono::SystemOptions options = ademono::SystemOptions::FromYaml(YAML::LoadFile(path), path);
  options.mapping.threaded = false;
  return options;
}

void Run(benchmark::State& state, bool tracking_only, bool ceres_pose = false) {
  const Data& data = LoadData();
  ademono::SystemOptions options = BenchOptions();
  options.pose.use_ceres = ceres_pose;
  auto system = std::make_unique<ademono::System>(data.sequence->GetCamera(), options);
  size_t i = 0;
  for (auto _ : state) {
    if (i == kFrames) {
      state.PauseTiming();
      system = std::make_unique<ademono::System>(data.sequence->GetCamera(), options);
      i = 0;
      state.ResumeTiming();
    }
    const ademono::TrackResult r = system->TrackFrame(data.frames[i], data.depths[i], {});
    if (tracking_only) state.SetIterationTime(r.tracking_ms / 1000.0);
    benchmark::DoNotOptimize(r.tracked);
    ++i;
  }
}

void BM_TrackingStep(benchmark::State& state) { Run(state, true, state.range(0) == 0); }
void BM_FrameNoDepthNoDetection(benchmark::State& state) { Run(state, false); }

// One iteration per frame of the slice: the reported time is the mean per frame.
BENCHMARK(BM_TrackingStep)
    ->Arg(0)
    ->Arg(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(kFrames);
BENCHMARK(BM_FrameNoDepthNoDetection)->Unit(benchmark::kMillisecond)->Iterations(kFrames);

}  // namespace

BENCHMARK_MAIN();
