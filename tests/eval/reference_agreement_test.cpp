// Reproduces what evo and kitti-odom-eval print for the trajectories in ../shared/data/trajectories
// (expected.json): evo values to 1e-6 relative, kitti-odom-eval values to its 3 printed decimals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "ademono/eval/trajectory_eval.h"

namespace fs = std::filesystem;

namespace ademono {
namespace {

const fs::path kTrajectories = fs::path(ADEMONO_SHARED_DIR) / "data" / "trajectories";

nlohmann::json LoadExpected() {
  std::ifstream in(kTrajectories / "expected.json");
  return nlohmann::json::parse(in);
}

// Largest deviations from evo, for docs/evaluation.md: relative over values >= 1e-3 (below that
// evo's 9 printed decimals dominate), absolute over all values.
double max_relative_deviation = 0.0;
double max_absolute_deviation = 0.0;

void ExpectStats(const ErrorStats& actual, const nlohmann::json& expected,
                 const std::string& what) {
  auto check = [&](const char* key, double value) {
    const double want = expected.at(key).get<double>();
    max_absolute_deviation = std::max(max_absolute_deviation, std::abs(value - want));
    if (std::abs(want) >= 1e-3) {
      max_relative_deviation =
          std::max(max_relative_deviation, std::abs(value - want) / std::abs(want));
    }
    // 1e-6 relative; values printed by evo with 9 decimals, so allow that rounding too.
    const double tol = std::max(1e-6 * std::abs(want), 1e-9);
    EXPECT_NEAR(value, want, tol) << what << " " << key;
  };
  check("rmse", actual.rmse);
  check("mean", actual.mean);
  check("median", actual.median);
  check("max", actual.max);
  check("min", actual.min);
  check("std", actual.std);
}

class EvoAgreementTest : public ::testing::TestWithParam<std::string> {};

TEST_P(EvoAgreementTest, MatchesEvo) {
  if (!fs::exists(kTrajectories / "expected.json")) GTEST_SKIP() << "no shared data";
  const nlohmann::json all = LoadExpected();
  const std::string name = GetParam();
  const auto files = all.at("evo_files").at(name);
  const TrajectoryFormat format = ParseTrajectoryFormat(files.at(2).get<std::string>());
  const PoseSeries gt = ReadPoseSeries(kTrajectories / files.at(0).get<std::string>(), format);
  const PoseSeries est = ReadPoseSeries(kTrajectories / files.at(1).get<std::string>(), format);
  const nlohmann::json& expected = all.at("evo").at(name);

  EvalOptions options;
  options.associate_by_timestamp = format != TrajectoryFormat::kKitti;
  size_t checked = 0;
  for (const auto& [key, stats] : expected.items()) {
    SCOPED_TRACE(name + " " + key);
    if (key.rfind("ape_", 0) == 0) {
      options.alignment = ParseAlignment(key.substr(4));
      ExpectStats(EvaluateTrajectories(gt, est, options).ape, stats, key);
      ++checked;
    } else if (key == "rpe_trans_1frame" || key == "rpe_rot_deg_1frame") {
      options.alignment = Alignment::kNone;
      options.rpe_delta = 1;
      options.rpe_unit = DeltaUnit::kFrames;
      const EvalResult r = EvaluateTrajectories(gt, est, options);
      ExpectStats(key == "rpe_trans_1frame" ? r.rpe_trans : r.rpe_rot_deg, stats, key);
      ++checked;
    } else if (key == "rpe_trans_100m") {
      options.alignment = Alignment::kNone;
      options.rpe_delta = 100;
      options.rpe_unit = DeltaUnit::kMeters;
      ExpectStats(EvaluateTrajectories(gt, est, options).rpe_trans, stats, key);
      ++checked;
    } else {
      ADD_FAILURE() << "unknown expected key " << key;
    }
  }
  EXPECT_GE(checked, 5u);
  std::cout << "deviation from evo so far: max relative (values >= 1e-3) " << max_relative_deviation
            << ", max absolute " << max_absolute_deviation << "\n";
}

INSTANTIATE_TEST_SUITE_P(AllPairs, EvoAgreementTest,
                         ::testing::Values("fr1_xyz_rgbdslam", "fr2_desk_orb", "kitti00_orb"));

TEST(KittiOdomEvalAgreementTest, MatchesPrintedValuesForAllAlignments) {
  if (!fs::exists(kTrajectories / "expected.json")) GTEST_SKIP() << "no shared data";
  const nlohmann::json expected = LoadExpected().at("kitti_odom_eval").at("example_1");
  size_t checked = 0;
  double max_abs = 0.0;
  for (const auto& [alignment_name, sequences] : expected.items()) {
    const KittiAlignment alignment = ParseKittiAlignment(alignment_name);
    for (const auto& [seq, values] : sequences.items()) {
      SCOPED_TRACE(alignment_name + " " + seq);
      const PoseSeries gt = ReadPoseSeries(
          kTrajectories / "kitti-odom-eval" / "gt" / (seq + ".txt"), TrajectoryFormat::kKitti);
      const PoseSeries est =
          ReadPoseSeries(kTrajectories / "kitti-odom-eval" / "example_1" / (seq + ".txt"),
                         TrajectoryFormat::kKitti);
      const KittiOdometryResult r =
          EvaluateKittiOdometry(gt.world_from_cam, est.world_from_cam, alignment);
      // Printed with 3 decimals: agree after rounding (half a unit of the last digit).
      EXPECT_NEAR(r.t_rel_percent, values.at("t_rel_percent").get<double>(), 5e-4 + 1e-9);
      EXPECT_NEAR(r.r_rel_deg_per_100m, values.at("r_rel_deg_per_100m").get<double>(), 5e-4 + 1e-9);
      EXPECT_NEAR(r.ate_m, values.at("ate_m").get<double>(), 5e-4 + 1e-9);
      EXPECT_NEAR(r.rpe_m, values.at("rpe_m").get<double>(), 5e-4 + 1e-9);
      EXPECT_NEAR(r.rpe_deg, values.at("rpe_deg").get<double>(), 5e-4 + 1e-9);
      EXPECT_GT(r.segments, 0u);
      max_abs =
          std::max({max_abs, std::abs(r.t_rel_percent - values.at("t_rel_percent").get<double>()),
                    std::abs(r.r_rel_deg_per_100m - values.at("r_rel_deg_per_100m").get<double>()),
                    std::abs(r.ate_m - values.at("ate_m").get<double>()),
                    std::abs(r.rpe_m - values.at("rpe_m").get<double>()),
                    std::abs(r.rpe_deg - values.at("rpe_deg").get<double>())});
      ++checked;
    }
  }
  EXPECT_EQ(checked, 8u);
  std::cout << "max absolute deviation from kitti-odom-eval's 3-decimal prints: " << max_abs
            << "\n";
}

}  // namespace
}  // namespace ademono
