#include "ademono/optimize/trajectory_smoothing.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

namespace ademono {
namespace {

Eigen::MatrixXd Dense(size_t n, double lambda) {
  Eigen::MatrixXd d2 = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n) - 2, n);
  for (Eigen::Index r = 0; r < d2.rows(); ++r) d2.row(r).segment<3>(r) << 1.0, -2.0, 1.0;
  return Eigen::MatrixXd::Identity(n, n) + lambda * d2.transpose() * d2;
}

TEST(TrajectorySmoothingTest, BandedFitAndHatTraceMatchTheDenseSystem) {
  for (size_t n : {3u, 4u, 5u, 17u}) {
    for (double lambda : {0.1, 3.0, 1000.0}) {
      std::vector<double> y(n);
      for (size_t i = 0; i < n; ++i) y[i] = std::sin(0.7 * static_cast<double>(i)) + 0.1 * i;
      double trace = 0.0;
      const std::vector<double> x = SmoothSeries(y, lambda, &trace);
      const Eigen::MatrixXd a = Dense(n, lambda);
      const Eigen::VectorXd expected =
          a.ldlt().solve(Eigen::Map<const Eigen::VectorXd>(y.data(), static_cast<Eigen::Index>(n)));
      for (size_t i = 0; i < n; ++i) EXPECT_NEAR(x[i], expected[i], 1e-9) << n << " " << lambda;
      EXPECT_NEAR(trace, a.inverse().trace(), 1e-9) << n << " " << lambda;
    }
  }
}

TEST(TrajectorySmoothingTest, GcvRemovesNoiseFromASmoothSeries) {
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.002);
  std::vector<double> truth, y;
  for (int i = 0; i < 300; ++i) {
    truth.push_back(0.3 * std::sin(2.0 * M_PI * i / 180.0));  // 6 s period at 30 frames/s
    y.push_back(truth.back() + noise(rng));
  }
  const SmoothedSeries s = SmoothSeriesGcv(y);
  double raw = 0.0, fitted = 0.0;
  for (size_t i = 0; i < y.size(); ++i) {
    raw += (y[i] - truth[i]) * (y[i] - truth[i]);
    fitted += (s.values[i] - truth[i]) * (s.values[i] - truth[i]);
  }
  EXPECT_LT(std::sqrt(fitted), 0.5 * std::sqrt(raw));
  EXPECT_GE(s.lambda, 10.0);
}

Rigid3d PoseAt(double t) {
  Rigid3d pose = Rigid3d::Identity();
  pose.linear() = ExpSO3(Eigen::Vector3d(0.1 * std::sin(t), 0.3 * t, 0.05 * std::cos(0.5 * t)));
  pose.translation() = Eigen::Vector3d(0.3 * std::sin(t), 0.2 * std::cos(0.7 * t), 0.1 * t);
  return pose;
}

TEST(TrajectorySmoothingTest, NoisyPosesComeCloserToTheTruth) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<double> times;
  std::vector<Rigid3d> truth, measured;
  for (int i = 0; i < 300; ++i) {
    times.push_back(i / 30.0);
    truth.push_back(PoseAt(times.back()));
    Rigid3d m = truth.back();
    m.translation() += 0.002 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    m.linear() = m.linear() * ExpSO3(0.0005 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
    measured.push_back(m);
  }
  PoseSmoothingReport report;
  const std::vector<Rigid3d> smoothed = SmoothPoses(times, measured, &report);
  double raw_t = 0, fit_t = 0, raw_r = 0, fit_r = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    raw_t += (measured[i].translation() - truth[i].translation()).squaredNorm();
    fit_t += (smoothed[i].translation() - truth[i].translation()).squaredNorm();
    raw_r += LogSO3(truth[i].linear().transpose() * measured[i].linear()).squaredNorm();
    fit_r += LogSO3(truth[i].linear().transpose() * smoothed[i].linear()).squaredNorm();
  }
  EXPECT_LT(fit_t, 0.25 * raw_t);  // errors at most half
  EXPECT_LT(fit_r, 0.25 * raw_r);
  EXPECT_EQ(report.segments, 1u);
  EXPECT_GT(report.rms_shift_m, 0.001);
  EXPECT_LT(report.max_shift_m, 0.01);
}

TEST(TrajectorySmoothingTest, ConstantVelocityIsKeptAndGapsSplitTheRun) {
  // Constant velocity and turn rate: the fit's null space, left exactly. Frames 20-24 are
  // missing and the camera jumps 10 cm over them; smoothing across the gap would bend both sides.
  std::vector<double> times;
  std::vector<Rigid3d> poses;
  for (int i = 0; i < 60; ++i) {
    if (i >= 20 && i < 25) continue;
    times.push_back(i / 30.0);
    Rigid3d pose = Rigid3d::Identity();
    pose.linear() = ExpSO3(Eigen::Vector3d(0.0, 0.01 * i, 0.0));
    pose.translation() = Eigen::Vector3d(0.01 * i + (i >= 25 ? 0.1 : 0.0), 0.0, 0.002 * i);
    poses.push_back(pose);
  }
  PoseSmoothingReport report;
  const std::vector<Rigid3d> smoothed = SmoothPoses(times, poses, &report);
  EXPECT_EQ(report.segments, 2u);
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_LT((smoothed[i].translation() - poses[i].translation()).norm(), 1e-9) << i;
    EXPECT_LT((smoothed[i].linear() - poses[i].linear()).norm(), 1e-9) << i;
  }
}

TEST(TrajectorySmoothingTest, ShortRunsAreReturnedAsTheyAre) {
  const std::vector<double> times{0.0, 0.1, 0.2};
  const std::vector<Rigid3d> poses{PoseAt(0.0), PoseAt(5.0), PoseAt(0.2)};
  const std::vector<Rigid3d> smoothed = SmoothPoses(times, poses);
  for (size_t i = 0; i < poses.size(); ++i) EXPECT_TRUE(smoothed[i].isApprox(poses[i]));
}

}  // namespace
}  // namespace ademono
