// End-to-end tests of `ademono eval`: results, JSON and SVG outputs, and bad input (one-line
// error naming the file, non-zero exit, no output file left behind).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_util.h"

namespace fs = std::filesystem;

namespace {

using ::testing::HasSubstr;

const fs::path kTraj = fs::path(ADEMONO_SHARED_DIR) / "data" / "trajectories";

using RunResult = ademono::cli_test::CliRun;
using ademono::cli_test::ReadFile;

class EvalCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kTraj / "expected.json")) GTEST_SKIP() << "no shared data";
    dir_ = ademono::cli_test::FreshTempDir(
        std::string("eval_cli_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  RunResult Run(const std::string& args) {
    return ademono::cli_test::RunAdemono("eval " + args, dir_);
  }
  static size_t Lines(const std::string& text) {
    return static_cast<size_t>(std::count(text.begin(), text.end(), '\n'));
  }
  static nlohmann::json Expected() {
    std::ifstream in(kTraj / "expected.json");
    return nlohmann::json::parse(in);
  }

  fs::path dir_;
};

TEST_F(EvalCliTest, TumSe3WritesJsonAndPlot) {
  const fs::path json = dir_ / "m.json", svg = dir_ / "p.svg";
  const RunResult r =
      Run("--gt " + (kTraj / "evo/freiburg1_xyz-groundtruth.txt").string() + " --est " +
          (kTraj / "evo/freiburg1_xyz-rgbdslam.txt").string() +
          " --format tum --align se3 --json " + json.string() + " --plot " + svg.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("APE translation"));
  const nlohmann::json j = nlohmann::json::parse(ReadFile(json));
  const nlohmann::json e = Expected()["evo"]["fr1_xyz_rgbdslam"];
  EXPECT_EQ(j["alignment"], "se3");
  EXPECT_NEAR(j["ape"]["rmse"].get<double>(), e["ape_se3"]["rmse"].get<double>(), 1e-8);
  EXPECT_NEAR(j["rpe_trans"]["mean"].get<double>(), e["rpe_trans_1frame"]["mean"].get<double>(),
              1e-8);
  EXPECT_NEAR(j["rpe_rot_deg"]["max"].get<double>(), e["rpe_rot_deg_1frame"]["max"].get<double>(),
              1e-6);
  for (const char* key : {"rmse", "mean", "median", "max", "min", "std"}) {
    EXPECT_TRUE(j["ape"].contains(key)) << key;
  }
  EXPECT_FALSE(j.contains("kitti"));
  EXPECT_FALSE(j.contains("scale"));
  EXPECT_GT(j["matched_poses"].get<int>(), 700);
  const std::string plot = ReadFile(svg);
  EXPECT_EQ(plot.rfind("<?xml", 0), 0u);
  EXPECT_THAT(plot, HasSubstr("</svg>"));
  EXPECT_THAT(plot, HasSubstr("<polyline"));
  // No temp files left beside the outputs.
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir_))
    files += entry.path().filename().string().rfind(".tmp", 0) == 0;
  EXPECT_EQ(files, 0u);
}

TEST_F(EvalCliTest, KittiMetricsAndSim3Scale) {
  const fs::path json = dir_ / "k.json";
  const RunResult r = Run("--gt " + (kTraj / "kitti-odom-eval/gt/10.txt").string() + " --est " +
                          (kTraj / "kitti-odom-eval/example_1/10.txt").string() +
                          " --format kitti --align sim3 --kitti-metrics --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(ReadFile(json));
  const nlohmann::json e = Expected()["kitti_odom_eval"]["example_1"]["7dof"]["10"];
  EXPECT_NEAR(j["kitti"]["t_rel_percent"].get<double>(), e["t_rel_percent"].get<double>(), 5e-4);
  EXPECT_NEAR(j["kitti"]["r_rel_deg_per_100m"].get<double>(), e["r_rel_deg_per_100m"].get<double>(),
              5e-4);
  EXPECT_EQ(j["kitti"]["alignment"], "7dof");
  EXPECT_TRUE(j.contains("scale"));
  EXPECT_GT(j["scale"].get<double>(), 0.5);
}

TEST_F(EvalCliTest, MixedFormatsEurocGroundTruthAgainstTumEstimate) {
  // The same five poses written as EuRoC CSV (ns) and as TUM (s): zero error with any alignment.
  std::ofstream euroc(dir_ / "gt.csv");
  std::ofstream tum(dir_ / "est.txt");
  std::ofstream kitti(dir_ / "est.kitti");
  euroc << "#timestamp [ns],p_x,p_y,p_z,q_w,q_x,q_y,q_z\n";
  for (int i = 0; i < 5; ++i) {
    const double x = 0.1 * i, y = 0.02 * i * i, z = 0.3 * (i % 2);
    euroc << 1403636579763555584LL + i * 50000000LL << "," << x << "," << y << "," << z
          << ",1,0,0,0\n";
    tum << std::setprecision(17) << 1403636579.763555584 + 0.05 * i << " " << x << " " << y << " "
        << z << " 0 0 0 1\n";
    kitti << "1 0 0 " << x << " 0 1 0 " << y << " 0 0 1 " << z << "\n";
  }
  euroc.close();
  tum.close();
  kitti.close();
  const fs::path json = dir_ / "mixed.json";
  RunResult r =
      Run("--gt " + (dir_ / "gt.csv").string() + " --gt-format euroc --est " +
          (dir_ / "est.txt").string() + " --est-format tum --align none --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(ReadFile(json));
  EXPECT_EQ(j["matched_poses"], 5);
  EXPECT_LT(j["ape"]["max"].get<double>(), 1e-6);
  // A KITTI estimate has no timestamps: matched by index.
  r = Run("--gt " + (dir_ / "gt.csv").string() + " --gt-format euroc --est " +
          (dir_ / "est.kitti").string() + " --est-format kitti --align none --json " +
          json.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(ReadFile(json));
  EXPECT_EQ(j["matched_poses"], 5);
  EXPECT_LT(j["ape"]["max"].get<double>(), 1e-9);
  // RPE 10 frames on 5 poses: no pairs, said plainly.
  r = Run("--gt " + (dir_ / "gt.csv").string() + " --gt-format euroc --est " +
          (dir_ / "est.txt").string() + " --est-format tum --rpe-delta 10");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("no pose pairs this far apart"));
}

TEST_F(EvalCliTest, SharedSplitsTwoEstimatesErrorsIntoWhatTheyShare) {
  // The same estimate twice shares all of its error; the ground truth against itself has none.
  const std::string gt = (kTraj / "evo/freiburg1_xyz-groundtruth.txt").string();
  const std::string est = (kTraj / "evo/freiburg1_xyz-rgbdslam.txt").string();
  const fs::path json = dir_ / "shared.json";
  RunResult r = Run("--gt " + gt + " --est " + est + " --est " + est +
                    " --align sim3 --shared --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("half their difference: 0.000000 m; correlation 1.00"));
  const nlohmann::json shared = nlohmann::json::parse(ReadFile(json))["shared"];
  EXPECT_EQ(shared["frames"].get<int>(), 785);
  EXPECT_NEAR(shared["shared_rmse"].get<double>(), shared["rmse_a"].get<double>(), 1e-12);
  EXPECT_GT(shared["rmse_a"].get<double>(), 0.005);
  r = Run("--gt " + gt + " --est " + est + " --est " + gt + " --align sim3 --shared --json " +
          json.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json half = nlohmann::json::parse(ReadFile(json))["shared"];
  EXPECT_NEAR(half["shared_rmse"].get<double>(), 0.5 * half["rmse_a"].get<double>(), 1e-9);
  EXPECT_NEAR(half["rmse_b"].get<double>(), 0.0, 1e-6);

  // --shared needs exactly two estimates: one line, exit 2, nothing written.
  const fs::path none = dir_ / "none.json";
  r = Run("--gt " + gt + " --est " + est + " --shared --json " + none.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "ademono eval: error: --shared compares exactly two --est, got 1\n");
  EXPECT_FALSE(fs::exists(none));
}

TEST_F(EvalCliTest, NoMatchingTimestampsNamesBothFiles) {
  const fs::path json = dir_ / "none.json";
  const std::string gt = (kTraj / "evo/freiburg1_xyz-groundtruth.txt").string();
  const std::string est = (kTraj / "evo/fr2_desk_ORB.txt").string();
  const RunResult r = Run("--gt " + gt + " --est " + est + " --json " + json.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(Lines(r.err), 1u) << r.err;
  EXPECT_THAT(r.err, HasSubstr("ademono eval: error: no matching timestamps within 0.01 s"));
  EXPECT_THAT(r.err, HasSubstr(gt));
  EXPECT_THAT(r.err, HasSubstr(est));
  EXPECT_FALSE(fs::exists(json));
}

TEST_F(EvalCliTest, KittiFilesOfDifferentLengths) {
  const fs::path json = dir_ / "len.json";
  const RunResult r = Run("--gt " + (kTraj / "kitti-odom-eval/gt/09.txt").string() + " --est " +
                          (kTraj / "kitti-odom-eval/example_1/10.txt").string() +
                          " --format kitti --json " + json.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(Lines(r.err), 1u) << r.err;
  EXPECT_THAT(r.err, HasSubstr("different lengths"));
  EXPECT_THAT(r.err, HasSubstr("09.txt (1591 poses)"));
  EXPECT_THAT(r.err, HasSubstr("10.txt (1201 poses)"));
  EXPECT_FALSE(fs::exists(json));
}

TEST_F(EvalCliTest, MalformedAndMissingFiles) {
  const fs::path json = dir_ / "bad.json", plot = dir_ / "bad.svg";
  const fs::path bad = dir_ / "est.txt";
  std::ofstream(bad) << "# ts tx ty tz qx qy qz qw\n1.0 0 0 0 0 0 0 1\n2.0 0 0 zero 0 0 0 1\n";
  const std::string gt = (kTraj / "evo/freiburg1_xyz-groundtruth.txt").string();
  RunResult r = Run("--gt " + gt + " --est " + bad.string() + " --json " + json.string() +
                    " --plot " + plot.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(Lines(r.err), 1u) << r.err;
  EXPECT_THAT(r.err, HasSubstr(bad.string() + ":3: field 4 'zero' is not a finite number"));
  EXPECT_FALSE(fs::exists(json));
  EXPECT_FALSE(fs::exists(plot));

  std::ofstream(bad) << "1 0 0 0 0 1 0 0 0 0 1\n";
  r = Run("--gt " + (kTraj / "kitti-odom-eval/gt/09.txt").string() + " --est " + bad.string() +
          " --format kitti --json " + json.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.err, HasSubstr(bad.string() + ":1: expected 12 fields, found 11"));
  EXPECT_FALSE(fs::exists(json));

  const std::string missing = (dir_ / "missing.txt").string();
  r = Run("--gt " + missing + " --est " + gt + " --json " + json.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(Lines(r.err), 1u) << r.err;
  EXPECT_THAT(r.err, HasSubstr(missing + ": no such file"));
  EXPECT_FALSE(fs::exists(json));
}

}  // namespace
