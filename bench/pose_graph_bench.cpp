// Time of one loop correction's essential graph (optimize/pose_graph) against the graph size: a
// ring of N keyframes with a drifted odometry chain, covisibility edges to the next 3 keyframes
// and one loop edge, solved as Sim(3) (network depth) and SE(3) (sensor depth).
#include <benchmark/benchmark.h>

#include <cmath>

#include "ademono/optimize/pose_graph.h"

namespace {

ademono::PoseGraphProblem MakeRing(int n, bool fix_scale) {
  using ademono::Sim3d;
  std::vector<Sim3d> truth;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    ademono::Rigid3d world_from_cam = ademono::Rigid3d::Identity();
    world_from_cam.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    world_from_cam.translation() = Eigen::Vector3d(20 * std::cos(a), 20 * std::sin(a), 0);
    truth.push_back(Sim3d::FromRigid(world_from_cam.inverse()));
  }
  ademono::PoseGraphProblem problem;
  problem.cam_from_world.push_back(truth[0]);
  for (int k = 1; k < n; ++k) {
    Sim3d step = truth[k] * truth[k - 1].Inverse();
    step.scale = 0.999;
    step.rotation =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.002, Eigen::Vector3d::UnitY())) * step.rotation;
    problem.cam_from_world.push_back(step * problem.cam_from_world.back());
  }
  for (int k = 1; k < n; ++k) {
    for (int d = 1; d <= 3 && d <= k; ++d) {
      const auto& p = problem.cam_from_world;
      problem.edges.push_back({static_cast<size_t>(k), static_cast<size_t>(k - d),
                               p[k] * p[k - d].Inverse()});
    }
  }
  problem.edges.push_back({static_cast<size_t>(n - 1), 0, truth[n - 1] * truth[0].Inverse()});
  problem.fixed.assign(n, false);
  problem.fixed[0] = true;
  problem.fix_scale = fix_scale;
  return problem;
}

void BM_EssentialGraph(benchmark::State& state) {
  const ademono::PoseGraphProblem problem =
      MakeRing(static_cast<int>(state.range(0)), state.range(1) != 0);
  for (auto _ : state) benchmark::DoNotOptimize(ademono::SolvePoseGraph(problem));
  state.SetLabel(state.range(1) ? "se3" : "sim3");
}
BENCHMARK(BM_EssentialGraph)
    ->ArgsProduct({{100, 500, 1000, 2000}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
