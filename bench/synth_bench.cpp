// Speed of the synthetic data generator: rendering one frame (ray casting, textures, masks'
// object ids) on ONE thread, the simulated depth network, and building a scene (textures).
#include <benchmark/benchmark.h>

#include <opencv2/core/utility.hpp>

#include "ademono/depth/simulated_depth.h"
#include "ademono/synth/generator.h"

namespace {

using ademono::synth::BuildScene;
using ademono::synth::GeneratorOptions;
using ademono::synth::RenderSceneFrame;
using ademono::synth::Scene;
using ademono::synth::SceneOptions;

void RenderFrames(benchmark::State& state, const std::string& scene_name) {
  cv::setNumThreads(1);  // the target is per core
  GeneratorOptions options;
  options.scene.scene = scene_name;
  options.scene.frames = 300;
  options.scene.persons = 3;
  options.scene.seed = 1;
  const Scene scene = BuildScene(options.scene);
  size_t frame = 0;
  for (auto _ : state) {
    auto rendered = RenderSceneFrame(scene, frame, options);
    benchmark::DoNotOptimize(rendered.image.data);
    frame = (frame + 7) % options.scene.frames;
  }
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel(std::to_string(scene.camera.width) + "x" + std::to_string(scene.camera.height));
}

void BM_RenderOffice(benchmark::State& state) { RenderFrames(state, "office"); }
BENCHMARK(BM_RenderOffice)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RenderStreet(benchmark::State& state) { RenderFrames(state, "street"); }
BENCHMARK(BM_RenderStreet)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_SimulatedDepth(benchmark::State& state) {
  cv::setNumThreads(1);
  ademono::SimulatedDepthOptions options;
  const ademono::SimulatedDepthProvider provider(options, nullptr);
  cv::Mat truth(480, 640, CV_32F);
  cv::randu(truth, 0.5, 8.0);
  size_t frame = 0;
  for (auto _ : state) benchmark::DoNotOptimize(provider.Degrade(truth, frame++).data);
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel("640x480");
}
BENCHMARK(BM_SimulatedDepth)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_BuildOfficeScene(benchmark::State& state) {
  cv::setNumThreads(1);
  SceneOptions options;
  for (auto _ : state) benchmark::DoNotOptimize(BuildScene(options).textures.size());
}
BENCHMARK(BM_BuildOfficeScene)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
