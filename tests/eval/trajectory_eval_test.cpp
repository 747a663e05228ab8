#include "ademono/eval/trajectory_eval.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

namespace ademono {
namespace {

using ::testing::HasSubstr;

Eigen::Matrix4d Pose(const Eigen::Vector3d& axis_angle, const Eigen::Vector3d& t) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = ExpSO3(axis_angle);
  m.topRightCorner<3, 1>() = t;
  return m;
}

// A wiggly 3D path (not degenerate for alignment).
PoseSeries MakePath(size_t n, double dt, double t0 = 0.0) {
  PoseSeries s;
  for (size_t i = 0; i < n; ++i) {
    const double a = 0.1 * static_cast<double>(i);
    s.timestamps.push_back(t0 + dt * static_cast<double>(i));
    s.world_from_cam.push_back(
        Pose({0.01 * a, 0.2 * std::sin(a), 0.05 * a}, {std::cos(a), std::sin(a), 0.3 * a}));
  }
  return s;
}

PoseSeries Transformed(const PoseSeries& s, const Eigen::Matrix4d& t, double scale) {
  PoseSeries out = s;
  for (auto& p : out.world_from_cam) {
    p.topRightCorner<3, 1>() *= scale;
    p = t * p;
  }
  return out;
}

TEST(ErrorStatsTest, MatchesNumpyDefinitions) {
  const ErrorStats s = ComputeStats({1, 2, 3, 4});
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));  // population std, ddof = 0
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_DOUBLE_EQ(s.max, 4);
  EXPECT_DOUBLE_EQ(ComputeStats({5, 1, 3}).median, 3);
}

TEST(AssociationTest, IteratesTheShorterTrajectoryAndAllowsRepeats) {
  // est is shorter: each est stamp picks its nearest gt stamp; two est stamps share gt[1].
  const std::vector<double> gt = {0.0, 0.1, 0.2, 0.3, 0.4};
  const std::vector<double> est = {0.098, 0.104, 0.35};
  const auto pairs = AssociateLikeEvo(gt, est, 0.01);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0], std::make_pair(size_t{1}, size_t{0}));
  EXPECT_EQ(pairs[1], std::make_pair(size_t{1}, size_t{1}));
  // Ties go to the first index, like np.argmin; |dt| == max_diff is accepted.
  const auto tie = AssociateLikeEvo({0.0, 1.0, 2.0, 3.0}, {0.5, 2.01}, 0.5);
  ASSERT_EQ(tie.size(), 2u);
  EXPECT_EQ(tie[0], std::make_pair(size_t{0}, size_t{0}));
  EXPECT_EQ(tie[1].first, 2u);
  // gt shorter: iterate gt.
  const auto swapped = AssociateLikeEvo({0.1}, {0.0, 0.095, 0.2}, 0.01);
  ASSERT_EQ(swapped.size(), 1u);
  EXPECT_EQ(swapped[0], std::make_pair(size_t{0}, size_t{1}));
}

TEST(UmeyamaTest, RecoversASimilarity) {
  const PoseSeries path = MakePath(40, 0.1);
  const Eigen::Matrix4d t = Pose({0.3, -0.2, 1.0}, {4, -2, 1});
  const PoseSeries moved = Transformed(path, t, 2.5);
  Eigen::Matrix3Xd src(3, 40), dst(3, 40);
  for (int i = 0; i < 40; ++i) {
    src.col(i) = path.world_from_cam[i].topRightCorner<3, 1>();
    dst.col(i) = moved.world_from_cam[i].topRightCorner<3, 1>();
  }
  const Similarity sim = UmeyamaAlignment(src, dst, true);
  EXPECT_NEAR(sim.scale, 2.5, 1e-10);
  EXPECT_TRUE(sim.rotation.isApprox(t.topLeftCorner<3, 3>(), 1e-10));
  EXPECT_TRUE(sim.translation.isApprox(t.topRightCorner<3, 1>(), 1e-10));
  EXPECT_EQ(UmeyamaAlignment(src, dst, false).scale, 1.0);

  Eigen::Matrix3Xd line(3, 5);
  for (int i = 0; i < 5; ++i) line.col(i) = Eigen::Vector3d(i, 2 * i, 0);
  EXPECT_THROW(UmeyamaAlignment(line, line, false), std::invalid_argument);
}

TEST(EvaluateTest, AlignmentsRemoveWhatTheyModel) {
  const PoseSeries gt = MakePath(60, 0.1, 100.0);
  const Eigen::Matrix4d t = Pose({0.1, 0.4, -0.3}, {1, 2, 3});
  EvalOptions options;
  options.max_diff = 0.01;

  // Rigidly moved estimate: se3 and origin give zero APE, none does not.
  const PoseSeries rigid = Transformed(gt, t, 1.0);
  options.alignment = Alignment::kSe3;
  EXPECT_LT(EvaluateTrajectories(gt, rigid, options).ape.max, 1e-9);
  options.alignment = Alignment::kOrigin;
  const EvalResult origin = EvaluateTrajectories(gt, rigid, options);
  EXPECT_LT(origin.ape.max, 1e-9);
  EXPECT_LT(origin.rpe_trans.max, 1e-9);
  options.alignment = Alignment::kNone;
  EXPECT_GT(EvaluateTrajectories(gt, rigid, options).ape.min, 0.1);

  // Scaled estimate: only sim3 removes it, and reports the inverse scale.
  const PoseSeries scaled = Transformed(gt, t, 0.5);
  options.alignment = Alignment::kSim3;
  const EvalResult sim = EvaluateTrajectories(gt, scaled, options);
  EXPECT_LT(sim.ape.max, 1e-9);
  EXPECT_NEAR(sim.gt_from_est.scale, 2.0, 1e-9);
  EXPECT_NEAR(ToJson(sim)["scale"].get<double>(), 2.0, 1e-9);
  options.alignment = Alignment::kSe3;
  EXPECT_GT(EvaluateTrajectories(gt, scaled, options).ape.rmse, 0.1);
}

TEST(EvaluateTest, RpeMeasuresAKnownPerturbation) {
  const PoseSeries gt = MakePath(11, 1.0);
  PoseSeries est = gt;
  // Every pose after 5 is shifted by 0.2 m along world x: one relative-pose jump of 0.2 m.
  for (size_t i = 6; i < est.size(); ++i) est.world_from_cam[i](0, 3) += 0.2;
  EvalOptions options;
  options.alignment = Alignment::kNone;
  const EvalResult r = EvaluateTrajectories(gt, est, options);
  EXPECT_EQ(r.rpe_trans.count, 10u);
  EXPECT_NEAR(r.rpe_trans.max, 0.2, 1e-12);
  EXPECT_NEAR(r.rpe_trans.min, 0.0, 1e-12);
  EXPECT_NEAR(r.rpe_rot_deg.max, 0.0, 1e-9);
  // delta 5 frames: pairs (0,5), (5,10).
  options.rpe_delta = 5;
  EXPECT_EQ(EvaluateTrajectories(gt, est, options).rpe_trans.count, 2u);
}

TEST(EvaluateTest, ReportsUnusableInput) {
  const PoseSeries gt = MakePath(10, 0.1);
  const PoseSeries late = MakePath(10, 0.1, 50.0);
  EvalOptions options;
  try {
    EvaluateTrajectories(gt, late, options);
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("no matching timestamps within 0.01 s"));
  }
  options.associate_by_timestamp = false;
  EXPECT_THROW(EvaluateTrajectories(gt, MakePath(9, 0.1), options), std::invalid_argument);
  options.rpe_delta = 0;
  EXPECT_THROW(EvaluateTrajectories(gt, gt, options), std::invalid_argument);
  EXPECT_THROW(ParseAlignment("sim2"), std::invalid_argument);
}

TEST(KittiOdometryTest, PerfectEstimateHasZeroErrorAndDriftIsMeasured) {
  // 1200 frames, 1 m apart along z: long enough for every length up to 800 m.
  std::vector<Eigen::Matrix4d> gt, est;
  for (int i = 0; i < 1200; ++i) {
    gt.push_back(Pose({0, 0.0005 * i, 0}, {0.01 * i, 0, static_cast<double>(i)}));
    Eigen::Matrix4d e = gt.back();
    e.topRightCorner<3, 1>() *= 1.02;  // 2 % scale drift
    est.push_back(e);
  }
  const KittiOdometryResult perfect = EvaluateKittiOdometry(gt, gt, KittiAlignment::kNone);
  EXPECT_NEAR(perfect.t_rel_percent, 0.0, 1e-9);
  EXPECT_NEAR(perfect.ate_m, 0.0, 1e-9);
  EXPECT_GT(perfect.segments, 100u);
  const KittiOdometryResult drift = EvaluateKittiOdometry(gt, est, KittiAlignment::kNone);
  EXPECT_NEAR(drift.t_rel_percent, 2.0, 0.05);
  EXPECT_NEAR(EvaluateKittiOdometry(gt, est, KittiAlignment::kScale).t_rel_percent, 0.0, 0.01);
  EXPECT_NEAR(EvaluateKittiOdometry(gt, est, KittiAlignment::kSevenDof).ate_m, 0.0, 1e-6);
}

TEST(PercentileTest, LinearBetweenOrderStatistics) {
  EXPECT_EQ(Percentile({}, 0.5), 0.0);
  EXPECT_EQ(Percentile({7.0}, 0.95), 7.0);
  const std::vector<double> v{4.0, 1.0, 3.0, 2.0};  // unsorted on purpose
  EXPECT_DOUBLE_EQ(Percentile(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(Percentile(v, 0.5), 2.5);    // numpy.percentile(v, 50)
  EXPECT_DOUBLE_EQ(Percentile(v, 0.95), 3.85);  // numpy.percentile(v, 95)
  EXPECT_DOUBLE_EQ(Percentile(v, 1.0), 4.0);
  EXPECT_DOUBLE_EQ(Percentile(v, 0.5), ComputeStats(v).median);
}

}  // namespace
}  // namespace ademono
