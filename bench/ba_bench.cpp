// One local bundle adjustment on a real problem recorded from 7-Scenes seq-a (sensor depth,
// configs/7scenes.yaml), tests/data/ba/seq_a_local_ba.bin, solved with each lever side by side:
// the built-in LM (optimize/schur_lm.h) against Ceres, auto-diff vs analytic Jacobians, Ceres'
// linear solver, iteration counts. Arguments of BM_LocalBa: jacobians (0 autodiff, 1 analytic;
// Ceres only), solver (0 sparse_schur, 1 dense_schur, 2 iterative_schur: Ceres; 3 the built-in LM).
// Ceres' threads are not a lever: 2 threads change the results' bits.
// BM_LocalBaIterations varies ba_first_iterations / ba_second_iterations (the default solver).
//
// Re-record the problem (the local BA of the last keyframe after --frames frames):
//   build/release/bench_ba --record=tests/data/ba/seq_a_local_ba.bin --frames=120
// A monocular window (--depth none, configs/network_indoor.yaml: 20 free keyframes, 2-dof rows),
// to time without committing it:
//   build/release/bench_ba --record=/tmp/none_ba.bin --frames=300 --depth=none
//     --config=configs/network_indoor.yaml
//   build/release/bench_ba --problem=/tmp/none_ba.bin --benchmark_filter=BM_LocalBa/analytic:1/solver:3
#include <benchmark/benchmark.h>
#include <yaml-cpp/yaml.h>

#include <cstring>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "ademono/core/memory.h"
#include "ademono/depth/depth_factory.h"
#include "ademono/io/sequence.h"
#include "ademono/optimize/bundle_adjustment.h"
#include "ademono/slam/system.h"

namespace {

std::string& ProblemPath() {
  static std::string path = std::string(ADEMONO_SOURCE_DIR) + "/tests/data/ba/seq_a_local_ba.bin";
  return path;
}

const ademono::BundleAdjustmentProblem& Problem() {
  static const ademono::BundleAdjustmentProblem problem =
      ademono::ReadBundleAdjustmentProblem(ProblemPath());
  return problem;
}

void Describe(benchmark::State& state, const ademono::BundleAdjustmentResult& result) {
  const auto& problem = Problem();
  int outliers = 0;
  for (bool o : result.outlier) outliers += o ? 1 : 0;
  state.counters["cameras"] = static_cast<double>(problem.cameras.size());
  state.counters["points"] = static_cast<double>(problem.points.size());
  state.counters["observations"] = static_cast<double>(problem.observations.size());
  state.counters["outliers"] = outliers;
}

void BM_LocalBa(benchmark::State& state) {
  ademono::BundleAdjustmentOptions options;
  options.analytic_jacobians = state.range(0) != 0;
  if (state.range(1) == 3) {
    options.solver = ademono::BaSolver::kLm;
  } else {
    options.solver = ademono::BaSolver::kCeres;
    options.linear_solver = static_cast<ademono::BaLinearSolver>(state.range(1));
  }
  ademono::BundleAdjustmentResult result;
  for (auto _ : state) {
    result = ademono::SolveBundleAdjustment(Problem(), options);
    benchmark::DoNotOptimize(result.points.data());
  }
  Describe(state, result);
}
BENCHMARK(BM_LocalBa)
    ->ArgNames({"analytic", "solver"})
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Args({1, 2})
    ->Args({1, 3})
    ->Unit(benchmark::kMillisecond);

void BM_LocalBaIterations(benchmark::State& state) {
  ademono::BundleAdjustmentOptions options;
  options.first_iterations = static_cast<int>(state.range(0));
  options.second_iterations = static_cast<int>(state.range(1));
  ademono::BundleAdjustmentResult result;
  for (auto _ : state) {
    result = ademono::SolveBundleAdjustment(Problem(), options);
    benchmark::DoNotOptimize(result.points.data());
  }
  Describe(state, result);
}
BENCHMARK(BM_LocalBaIterations)
    ->ArgNames({"first", "second"})
    ->Args({5, 10})
    ->Args({5, 5})
    ->Args({3, 5})
    ->Unit(benchmark::kMillisecond);

// Runs seq-a frames [0, frames) with `config` and `depth` and writes the last local BA problem.
int Record(const std::string& path, size_t frames, const std::string& config,
           const std::string& depth) {
  const ademono::SystemOptions options =
      ademono::SystemOptions::FromYaml(YAML::LoadFile(config), config);
  auto sequence =
      ademono::OpenSequence(std::string("7scenes:") + ADEMONO_SHARED_DIR + "/data/7scenes-seq-a");
  ademono::DepthFactoryContext context;
  context.sequence = sequence.get();
  auto provider = ademono::MakeDepthProvider(depth, context);
  ademono::BundleAdjustmentProblem last;
  ademono::SetBundleAdjustmentObserver(
      [&last](const ademono::BundleAdjustmentProblem& problem) { last = problem; });
  ademono::System system(sequence->GetCamera(), options);
  for (size_t i = 0; i < frames && i < sequence->Size(); ++i) {
    const ademono::FrameData frame = sequence->Load(i);
    system.TrackFrame(
        frame, provider ? provider->Depth(frame, sequence->GetCamera()) : cv::Mat(), {});
  }
  ademono::SetBundleAdjustmentObserver(nullptr);
  if (last.observations.empty()) {
    std::cerr << "bench_ba: no local bundle adjustment in " << frames << " frames\n";
    return 2;
  }
  ademono::WriteBundleAdjustmentProblem(last, path);
  std::cout << path << ": " << last.cameras.size() << " cameras, " << last.points.size()
            << " points, " << last.observations.size() << " observations\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // As the ademono executable: without it every solve faults its linearisation's pages in again
  // (a monocular window of 20 free keyframes: 73 ms instead of the run's 22 ms).
  ademono::KeepLargeBuffersInTheHeap(ademono::kMmapThresholdBytes, ademono::kTrimThresholdBytes);
  std::string record, depth = "sensor";
  std::string config = std::string(ADEMONO_SOURCE_DIR) + "/configs/7scenes.yaml";
  size_t frames = 120;
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    if (std::strncmp(argv[i], "--record=", 9) == 0) {
      record = argv[i] + 9;
    } else if (std::strncmp(argv[i], "--frames=", 9) == 0) {
      frames = std::stoul(argv[i] + 9);
    } else if (std::strncmp(argv[i], "--depth=", 8) == 0) {
      depth = argv[i] + 8;
    } else if (std::strncmp(argv[i], "--config=", 9) == 0) {
      config = argv[i] + 9;
    } else if (std::strncmp(argv[i], "--problem=", 10) == 0) {
      ProblemPath() = argv[i] + 10;
    } else {
      rest.push_back(argv[i]);
    }
  }
  // A missing or bad file, config or dataset: one line and exit 2, not an abort mid-benchmark.
  try {
    if (!record.empty()) return Record(record, frames, config, depth);
    Problem();
  } catch (const std::exception& e) {
    std::cerr << "bench_ba: " << e.what() << "\n";
    return 2;
  }
  argc = static_cast<int>(rest.size());
  argv = rest.data();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
