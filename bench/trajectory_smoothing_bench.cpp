// Time of smoothing a run's written trajectory (optimize/trajectory_smoothing: 17 lambdas x 6
// coordinates, each a banded solve and the trace of its inverse) against the number of frames.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "ademono/optimize/trajectory_smoothing.h"

namespace {

void BM_SmoothPoses(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.002);
  std::vector<double> times;
  std::vector<ademono::Rigid3d> poses;
  for (int i = 0; i < n; ++i) {
    const double t = i / 30.0;
    times.push_back(t);
    ademono::Rigid3d pose = ademono::Rigid3d::Identity();
    pose.linear() = ademono::ExpSO3(Eigen::Vector3d(0.1 * std::sin(t), 0.3 * t, 0.0));
    pose.translation() = Eigen::Vector3d(0.3 * std::sin(t) + noise(rng), noise(rng), 0.1 * t);
    poses.push_back(pose);
  }
  for (auto _ : state) benchmark::DoNotOptimize(ademono::SmoothPoses(times, poses));
  state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(BM_SmoothPoses)->Arg(600)->Arg(3000)->Arg(30000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
