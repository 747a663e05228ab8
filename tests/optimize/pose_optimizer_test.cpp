#include "ademono/optimize/pose_optimizer.h"

#include <gtest/gtest.h>

#include <random>

namespace ademono {
namespace {

constexpr PinholeIntrinsics kIntrinsics{585, 585, 320, 240, 585 * 0.08};

Rigid3d TruePose() {
  Rigid3d pose = Rigid3d::Identity();
  pose.linear() =
      Eigen::AngleAxisd(0.1, Eigen::Vector3d(0.2, 1, 0.1).normalized()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.1, -0.05, 0.2);
  return pose;
}

std::vector<PoseObservation> MakeObservations(const Rigid3d& cam_from_world, int n, bool depth,
                                              std::mt19937& rng) {
  std::uniform_real_distribution<double> xy(-1.5, 1.5), z(1.0, 4.0);
  std::normal_distribution<double> noise(0.0, 0.5);
  std::vector<PoseObservation> observations;
  const Rigid3d world_from_cam = cam_from_world.inverse();
  while (static_cast<int>(observations.size()) < n) {
    const Eigen::Vector3d pc(xy(rng), xy(rng), z(rng));
    const double u = kIntrinsics.fx * pc.x() / pc.z() + kIntrinsics.cx;
    const double v = kIntrinsics.fy * pc.y() / pc.z() + kIntrinsics.cy;
    if (u < 0 || u > 640 || v < 0 || v > 480) continue;
    PoseObservation o;
    o.point_world = world_from_cam * pc;
    o.image.pixel = Eigen::Vector2d(u + noise(rng), v + noise(rng));
    if (depth) o.image.u_right = u - kIntrinsics.bf / pc.z() + noise(rng);
    observations.push_back(o);
  }
  return observations;
}

double TranslationError(const Rigid3d& a, const Rigid3d& b) {
  return (a.inverse().translation() - b.inverse().translation()).norm();
}

TEST(PoseOptimizerTest, RecoversPoseFromPerturbedStartWithDepth) {
  std::mt19937 rng(1);
  const Rigid3d truth = TruePose();
  const auto observations = MakeObservations(truth, 300, true, rng);
  Rigid3d start = truth;
  start.translation() += Eigen::Vector3d(0.05, -0.03, 0.04);
  start.linear() =
      start.linear() * Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const PoseOptimizationResult result = OptimizePose(kIntrinsics, start, observations);
  EXPECT_LT(TranslationError(result.cam_from_world, truth), 0.005);
  EXPECT_GT(result.num_inliers, 270);
}

TEST(PoseOptimizerTest, MonocularObservationsAlsoConverge) {
  std::mt19937 rng(2);
  const Rigid3d truth = TruePose();
  const auto observations = MakeObservations(truth, 300, false, rng);
  Rigid3d start = truth;
  start.translation() += Eigen::Vector3d(0.02, 0.02, -0.02);
  const PoseOptimizationResult result = OptimizePose(kIntrinsics, start, observations);
  EXPECT_LT(TranslationError(result.cam_from_world, truth), 0.01);
}

TEST(PoseOptimizerTest, FlagsGrossOutliers) {
  std::mt19937 rng(3);
  const Rigid3d truth = TruePose();
  auto observations = MakeObservations(truth, 200, true, rng);
  for (size_t i = 0; i < observations.size(); i += 5)
    observations[i].image.pixel += Eigen::Vector2d(40, -30);
  const PoseOptimizationResult result = OptimizePose(kIntrinsics, truth, observations);
  for (size_t i = 0; i < observations.size(); i += 5) EXPECT_TRUE(result.outlier[i]) << i;
  EXPECT_LT(TranslationError(result.cam_from_world, truth), 0.005);
  EXPECT_NEAR(result.num_inliers, 160, 8);
}

TEST(PoseOptimizerTest, DeterministicAndEmptyInput) {
  std::mt19937 rng(4);
  const Rigid3d truth = TruePose();
  const auto observations = MakeObservations(truth, 100, true, rng);
  Rigid3d start = truth;
  start.translation() += Eigen::Vector3d(0.01, 0, 0);
  const auto a = OptimizePose(kIntrinsics, start, observations);
  const auto b = OptimizePose(kIntrinsics, start, observations);
  EXPECT_TRUE(a.cam_from_world.matrix() == b.cam_from_world.matrix());
  const auto empty = OptimizePose(kIntrinsics, start, {});
  EXPECT_TRUE(empty.cam_from_world.matrix() == start.matrix());
  EXPECT_THROW(OptimizePose(kIntrinsics, start, observations, {0, 10, false}),
               std::invalid_argument);
}

// The built-in Levenberg-Marquardt and Ceres solve the same problem: same outliers, poses equal
// far below the noise, with depth, without, and with gross outliers (Huber rounds matter).
TEST(PoseOptimizerTest, BuiltInSolverAgreesWithCeres) {
  std::mt19937 rng(5);
  const Rigid3d truth = TruePose();
  for (const bool depth : {true, false}) {
    auto observations = MakeObservations(truth, 250, depth, rng);
    for (size_t i = 0; i < observations.size(); i += 7)
      observations[i].image.pixel += Eigen::Vector2d(25, 12);
    Rigid3d start = truth;
    start.translation() += Eigen::Vector3d(0.04, -0.02, 0.03);
    start.linear() =
        start.linear() * Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitX()).toRotationMatrix();
    PoseOptimizerOptions lm_options, ceres_options;
    ceres_options.use_ceres = true;
    const auto lm = OptimizePose(kIntrinsics, start, observations, lm_options);
    const auto ceres = OptimizePose(kIntrinsics, start, observations, ceres_options);
    EXPECT_EQ(lm.outlier, ceres.outlier) << depth;
    EXPECT_EQ(lm.num_inliers, ceres.num_inliers) << depth;
    EXPECT_LT((lm.cam_from_world.matrix() - ceres.cam_from_world.matrix()).norm(), 1e-7) << depth;
    EXPECT_LT(TranslationError(lm.cam_from_world, truth), depth ? 0.005 : 0.01) << depth;
    for (size_t i = 0; i < observations.size(); i += 7) EXPECT_TRUE(lm.outlier[i]) << i;
  }
  // Auto-diff Jacobians exist only through Ceres.
  PoseOptimizerOptions bad;
  bad.analytic_jacobians = false;
  EXPECT_THROW(OptimizePose(kIntrinsics, truth, MakeObservations(truth, 20, true, rng), bad),
               std::invalid_argument);
}

}  // namespace
}  // namespace ademono
