#include "ademono/optimize/pose_graph.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace ademono {
namespace {

// A ring of n cameras on a circle (radius 2 m, or `radius`), each looking outwards.
std::vector<Sim3d> Ring(int n, double radius = 2) {
  std::vector<Sim3d> poses;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    Rigid3d world_from_cam = Rigid3d::Identity();
    world_from_cam.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    world_from_cam.translation() = Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), 0);
    poses.push_back(Sim3d::FromRigid(world_from_cam.inverse()));
  }
  return poses;
}

double MaxCentreError(const std::vector<Sim3d>& a, const std::vector<Sim3d>& b) {
  double worst = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    const Eigen::Vector3d ca = a[k].Inverse().translation, cb = b[k].Inverse().translation;
    worst = std::max(worst, (ca - cb).norm());
  }
  return worst;
}

// Odometry around the ring `truth`: each step cam_k_from_cam_{k-1} as `perturb` makes it, chained
// from the first (fixed) camera into `drifted`, and closed by one exact loop edge from the last
// camera to the first.
template <typename Perturb>
PoseGraphProblem DriftedRingWithLoop(const std::vector<Sim3d>& truth, Perturb perturb,
                                     std::vector<Sim3d>* drifted) {
  const size_t n = truth.size();
  PoseGraphProblem problem;
  drifted->assign(1, truth[0]);
  for (size_t k = 1; k < n; ++k) {
    const Sim3d noisy = perturb(k, truth[k] * truth[k - 1].Inverse());
    drifted->push_back(noisy * drifted->back());
    problem.edges.push_back({k, k - 1, noisy});  // the edges measure the drifted odometry
  }
  problem.edges.push_back({n - 1, 0, truth[n - 1] * truth[0].Inverse()});
  problem.cam_from_world = *drifted;
  problem.fixed.assign(n, false);
  problem.fixed[0] = true;
  problem.iterations = 50;
  return problem;
}

TEST(Sim3d, ComposeAndInverse) {
  Sim3d s;
  s.scale = 1.3;
  s.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()));
  s.translation = {0.5, -1, 2};
  const Eigen::Vector3d x(0.3, 0.2, -0.7);
  EXPECT_LT(((s.Inverse() * s) * x - x).norm(), 1e-12);
  EXPECT_LT((s * (s.Inverse() * x) - x).norm(), 1e-12);
  const Rigid3d r = s.ToRigid();
  EXPECT_LT((r.translation() - s.translation / 1.3).norm(), 1e-12);
}

// Odometry that drifted in scale and heading around a ring, closed by one loop edge: the Sim(3)
// graph spreads the correction; SE(3) cannot undo a scale drift as well.
TEST(PoseGraph, LoopEdgeRemovesAccumulatedDrift) {
  const int n = 24;
  const std::vector<Sim3d> truth = Ring(n);
  // Drifted chain: each odometry step shrinks the scale by 3 % (a Sim(3) step, as a drifting
  // network scale) and adds a 1 degree error about the camera's y axis; the loop edge is exact.
  std::vector<Sim3d> drifted;
  const PoseGraphProblem problem = DriftedRingWithLoop(
      truth,
      [](size_t, Sim3d step) {
        step.scale = 0.97;
        step.rotation =
            Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 180, Eigen::Vector3d::UnitY())) *
            step.rotation;
        return step;
      },
      &drifted);
  const double before = MaxCentreError(drifted, truth);
  ASSERT_GT(before, 0.5);
  const PoseGraphResult result = SolvePoseGraph(problem);
  EXPECT_LT(result.final_cost, result.initial_cost);
  // The loop edge pulls the last camera back onto the first one's measured relation.
  const Sim3d last = result.cam_from_world[n - 1];
  const Eigen::Vector3d gap = last.Inverse().translation - truth[n - 1].Inverse().translation;
  EXPECT_LT(gap.norm(), 0.5 * (drifted[n - 1].Inverse().translation -
                               truth[n - 1].Inverse().translation)
                                  .norm());
  EXPECT_LT(MaxCentreError(result.cam_from_world, truth), 0.6 * before);
  // The fixed vertex does not move.
  EXPECT_LT((result.cam_from_world[0].translation - truth[0].translation).norm(), 1e-12);

  PoseGraphProblem se3 = problem;
  se3.fix_scale = true;
  const PoseGraphResult rigid = SolvePoseGraph(se3);
  // SE(3): every scale keeps its start value.
  for (int k = 0; k < n; ++k) EXPECT_NEAR(rigid.cam_from_world[k].scale, drifted[k].scale, 1e-12);
}

double MaxRotationError(const std::vector<Sim3d>& a, const std::vector<Sim3d>& b) {
  double worst = 0;
  for (size_t k = 0; k < a.size(); ++k)
    worst = std::max(worst, a[k].rotation.angularDistance(b[k].rotation));
  return worst;
}

// Odometry whose error is in translation only (20 of 80 steps 4 cm off sideways, no rotation
// error) around a ring of 40 m radius seen at 25 m depth, closed by one exact loop edge. With
// identity information a metre weighs like a radian, so the graph closes the gap largely by
// turning the chain (a thousandth of a radian per edge moves the far end by metres) and leaves
// rotation errors where there were none; with the translation residual in units of the scene
// depth more of the gap goes into the steps' translations.
TEST(PoseGraph, DepthWeightedTranslationTurnsTheChainLess) {
  const int n = 80;
  const double depth = 25;
  const std::vector<Sim3d> truth = Ring(n, 40.0);
  std::vector<Sim3d> drifted;
  const PoseGraphProblem problem = DriftedRingWithLoop(
      truth,
      [](size_t k, Sim3d step) {
        if (k > 10 && k <= 30) step.translation += Eigen::Vector3d(0.04, 0, 0);
        return step;
      },
      &drifted);
  const double before = MaxCentreError(drifted, truth);
  ASSERT_GT(before, 0.5);
  ASSERT_LT(MaxRotationError(drifted, truth), 1e-9);
  PoseGraphProblem weighted = problem;
  for (PoseGraphEdge& e : weighted.edges) e.sqrt_information.segment<3>(3).setConstant(1 / depth);
  const std::vector<Sim3d> identity = SolvePoseGraph(problem).cam_from_world;
  const std::vector<Sim3d> by_depth = SolvePoseGraph(weighted).cam_from_world;
  // Measured: identity 0.559 m and 3.1 mrad, by depth 0.522 m and 2.2 mrad (drift 0.720 m).
  EXPECT_LT(MaxRotationError(by_depth, truth), 0.8 * MaxRotationError(identity, truth));
  EXPECT_LT(MaxCentreError(by_depth, truth), MaxCentreError(identity, truth));
  EXPECT_LT(MaxCentreError(by_depth, truth), 0.8 * before);
}

TEST(PoseGraph, RejectsBadEdges) {
  PoseGraphProblem problem;
  problem.cam_from_world = Ring(3);
  problem.fixed = {true, false, false};
  problem.edges.push_back({0, 5, Sim3d()});
  EXPECT_THROW(SolvePoseGraph(problem), std::invalid_argument);
}

}  // namespace
}  // namespace ademono
