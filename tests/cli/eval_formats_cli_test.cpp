// `ademono eval` on the files other tools write: kitti-odom-eval's indexed KITTI files (detected,
// the format said), several estimates in one table / JSON / plot (evo_res), and the one-line
// errors for files that cannot be compared.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_util.h"

namespace fs = std::filesystem;

namespace {

using ::testing::HasSubstr;

const fs::path kTraj = fs::path(ADEMONO_SHARED_DIR) / "data" / "trajectories";

class EvalFormatsCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kTraj / "expected.json")) GTEST_SKIP() << "no shared data";
    dir_ = ademono::cli_test::FreshTempDir(
        std::string("eval_formats_") +
        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::ifstream in(kTraj / "expected.json");
    expected_ = nlohmann::json::parse(in);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  ademono::cli_test::CliRun Run(const std::string& args) {
    return ademono::cli_test::RunAdemono("eval " + args, dir_);
  }
  // kitti-odom-eval's result file layout: "index r11 ... t3", the numbers' text kept.
  fs::path Indexed(const std::string& seq) {
    std::ifstream in(kTraj / "kitti-odom-eval" / "example_1" / (seq + ".txt"));
    const fs::path out_path = dir_ / (seq + ".txt");
    std::ofstream out(out_path);
    std::string line;
    for (int index = 0; std::getline(in, line); ++index) out << index << " " << line << "\n";
    return out_path;
  }

  fs::path dir_;
  nlohmann::json expected_;
};

TEST_F(EvalFormatsCliTest, IndexedKittiIsDetectedAndReproducesKittiOdomEval) {
  const fs::path est = Indexed("10"), json = dir_ / "k.json";
  const std::string gt = (kTraj / "kitti-odom-eval/gt/10.txt").string();
  const auto r =
      Run("--gt " + gt + " --est " + est.string() + " --kitti-align 7dof --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("ground truth: " + gt + " (kitti, detected, 1201 poses)"));
  EXPECT_THAT(r.out, HasSubstr("estimate: " + est.string() + " (kitti-indexed, detected"));
  const auto& e = expected_["kitti_odom_eval"]["example_1"]["7dof"]["10"];
  char printed[256];
  std::snprintf(printed, sizeof(printed), "t_rel %.3f %%  r_rel %.3f deg/100m  ATE %.3f m",
                e["t_rel_percent"].get<double>(), e["r_rel_deg_per_100m"].get<double>(),
                e["ate_m"].get<double>());
  EXPECT_THAT(r.out, HasSubstr(printed));
  const nlohmann::json j = nlohmann::json::parse(ademono::cli_test::ReadFile(json));
  EXPECT_EQ(j["est_file"]["format"], "kitti-indexed");
  EXPECT_EQ(j["est_file"]["format_detected"], true);
  EXPECT_NEAR(j["kitti"]["rpe_deg"].get<double>(), e["rpe_deg"].get<double>(), 5e-4 + 1e-9);

  // Named formats: "kitti" reads the indexed file too; "tum" rejects it on its first line.
  auto named = Run("--gt " + gt + " --est " + est.string() + " --format kitti --kitti-metrics");
  ASSERT_EQ(named.exit_code, 0) << named.err;
  EXPECT_THAT(named.out, HasSubstr("(kitti-indexed, as given, 1201 poses)"));
  named = Run("--gt " + gt + " --est " + est.string() + " --format tum");
  EXPECT_EQ(named.exit_code, 2);
  EXPECT_THAT(named.err, HasSubstr(gt + ":1: expected 8 fields, found 12"));
}

TEST_F(EvalFormatsCliTest, SeveralEstimatesOneTableJsonAndPlot) {
  const fs::path json = dir_ / "all.json", svg = dir_ / "all.svg";
  const std::string gt = (kTraj / "evo/freiburg1_xyz-groundtruth.txt").string();
  const std::string a = (kTraj / "evo/freiburg1_xyz-rgbdslam.txt").string();
  // A second estimate: the same poses written as EuRoC CSV.
  const fs::path b = dir_ / "b.csv";
  {
    std::ifstream in(a);
    std::ofstream out(b);
    out << "#timestamp [ns],p_x,p_y,p_z,q_w,q_x,q_y,q_z\n";
    std::string t, x, y, z, qx, qy, qz, qw, line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream f(line);
      f >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
      std::string frac = t.substr(t.find('.') + 1);
      frac.resize(9, '0');
      out << t.substr(0, t.find('.')) << frac << "," << x << "," << y << "," << z << "," << qw
          << "," << qx << "," << qy << "," << qz << "\n";
    }
  }
  const auto r = Run("--gt " + gt + " --est " + a + " --est " + b.string() + " --align se3" +
                     " --json " + json.string() + " --plot " + svg.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("estimate: " + b.string() + " (euroc, detected, 788 poses)"));
  // One header row and one row per estimate, APE rmse as evo prints it (6 decimals here).
  char rmse[32];
  std::snprintf(rmse, sizeof(rmse), "%.6f",
                expected_["evo"]["fr1_xyz_rgbdslam"]["ape_se3"]["rmse"].get<double>());
  EXPECT_THAT(r.out, HasSubstr("APE rmse"));
  size_t rows = 0;
  for (size_t at = r.out.find(rmse); at != std::string::npos; at = r.out.find(rmse, at + 1)) ++rows;
  EXPECT_EQ(rows, 2u) << r.out;
  const nlohmann::json j = nlohmann::json::parse(ademono::cli_test::ReadFile(json));
  ASSERT_EQ(j["estimates"].size(), 2u);
  EXPECT_EQ(j["gt_file"]["format"], "tum");
  EXPECT_EQ(j["estimates"][1]["est_file"]["format"], "euroc");
  for (const auto& e : j["estimates"]) {
    EXPECT_NEAR(e["ape"]["rmse"].get<double>(),
                expected_["evo"]["fr1_xyz_rgbdslam"]["ape_se3"]["rmse"].get<double>(), 1e-8);
    EXPECT_EQ(e["matched_poses"], j["estimates"][0]["matched_poses"]);
  }
  const std::string plot = ademono::cli_test::ReadFile(svg);
  EXPECT_THAT(plot, HasSubstr("2 estimates, alignment se3"));
  // Ground truth, two estimates in the top view, two APE curves.
  size_t polylines = 0;
  for (size_t at = plot.find("<polyline"); at != std::string::npos;
       at = plot.find("<polyline", at + 1))
    ++polylines;
  EXPECT_EQ(polylines, 5u);
}

TEST_F(EvalFormatsCliTest, ErrorsNameTheFilesAndWriteNothing) {
  const fs::path json = dir_ / "e.json";
  const fs::path est = Indexed("09");
  const std::string tum_gt = (kTraj / "evo/freiburg1_xyz-groundtruth.txt").string();
  // Indexed against timestamped: refused, both files named.
  auto r = Run("--gt " + tum_gt + " --est " + est.string() + " --json " + json.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("cannot be compared with a timestamped file"));
  EXPECT_THAT(r.err, HasSubstr(est.string()));
  EXPECT_FALSE(fs::exists(json));
  // An index beyond the ground truth (09 against the shorter sequence 10).
  r = Run("--gt " + (kTraj / "kitti-odom-eval/gt/10.txt").string() + " --est " + est.string() +
          " --json " + json.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("estimate frame index 1201 has no ground-truth pose between"));
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);
  EXPECT_FALSE(fs::exists(json));
  // One bad estimate among several: nothing written.
  const fs::path bad = dir_ / "bad.txt";
  std::ofstream(bad) << "1 2 3\n";
  r = Run("--gt " + tum_gt + " --est " + tum_gt + " --est " + bad.string() + " --json " +
          json.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err,
              HasSubstr(bad.string() + ":1: cannot tell the trajectory format from 3 fields"));
  EXPECT_FALSE(fs::exists(json));
}

}  // namespace
