// tools/compare_odometry.py end to end on 4 real 7-Scenes frames (OpenCV RgbdOdometry only, to
// stay fast): it writes the ground truth and the method's TUM trajectory, scores them with the
// CLI, and puts an --extra trajectory in the same table. Bad input exits 2 with one message.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_util.h"

namespace fs = std::filesystem;

namespace {

namespace cli_test = ademono::cli_test;
using ::testing::HasSubstr;

const fs::path kSeq = fs::path(ADEMONO_SHARED_DIR) / "data" / "7scenes-seq-a";
const fs::path kTool = fs::path(ADEMONO_SOURCE_DIR) / "tools" / "compare_odometry.py";

bool HavePythonDeps() {
  return std::system("/usr/bin/python3 -c 'import cv2, numpy; cv2.rgbd' >/dev/null 2>&1") == 0;
}

// The tool with stdout and stderr captured separately.
int RunTool(const std::string& args, const fs::path& dir, std::string* out, std::string* err) {
  const cli_test::CliRun run = cli_test::RunCommand(
      "/usr/bin/python3 " + kTool.string() + " --ademono " + ADEMONO_CLI + " " + args, dir);
  *out = run.out;
  *err = run.err;
  return run.exit_code;
}

TEST(CompareOdometryTest, ScoresOpenCvOdometryAndAnExtraTrajectory) {
  if (!fs::exists(kSeq) || !HavePythonDeps()) GTEST_SKIP() << "no 7-Scenes data or cv2.rgbd";
  const fs::path dir = cli_test::FreshTempDir("cmp");
  // The extra trajectory: the ground truth itself, shifted by 1 cm along x (ATE 0 after se3).
  std::string out, err;
  ASSERT_EQ(RunTool("--sequence " + kSeq.string() + " --out " + (dir / "cmp").string() +
                        " --frames 4 --methods cv_rgbd --json " + (dir / "t.json").string(),
                    dir, &out, &err),
            0)
      << err;
  EXPECT_THAT(out, HasSubstr("| cv_rgbd |"));
  ASSERT_TRUE(fs::exists(dir / "cmp" / "groundtruth.txt"));
  ASSERT_TRUE(fs::exists(dir / "cmp" / "cv_rgbd.txt"));
  const nlohmann::json table = nlohmann::json::parse(cli_test::ReadFile(dir / "t.json"));
  ASSERT_EQ(table["rows"].size(), 1u);
  EXPECT_EQ(table["rows"][0]["matched"], 4);
  // Four frames barely move: frame-to-frame odometry stays within a centimetre.
  EXPECT_LT(table["rows"][0]["ate_rmse"].get<double>(), 0.01);

  std::ifstream gt(dir / "cmp" / "groundtruth.txt");
  std::ofstream shifted(dir / "shifted.txt");
  std::string line;
  while (std::getline(gt, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ss(line);
    double v[8];
    for (double& x : v) ss >> x;
    shifted << std::setprecision(12) << v[0] << " " << v[1] + 0.01 << " " << v[2] << " " << v[3]
            << " " << v[4] << " " << v[5] << " " << v[6] << " " << v[7] << "\n";
  }
  shifted.close();
  ASSERT_EQ(RunTool("--sequence " + kSeq.string() + " --out " + (dir / "cmp").string() +
                        " --frames 4 --methods cv_rgbd --extra shifted=" +
                        (dir / "shifted.txt").string() + " --json " + (dir / "t.json").string(),
                    dir, &out, &err),
            0)
      << err;
  const nlohmann::json both = nlohmann::json::parse(cli_test::ReadFile(dir / "t.json"));
  ASSERT_EQ(both["rows"].size(), 2u);
  EXPECT_EQ(both["rows"][1]["method"], "shifted");
  EXPECT_LT(both["rows"][1]["ate_rmse"].get<double>(), 1e-6);
  EXPECT_THAT(out, HasSubstr("| shifted |"));

  EXPECT_EQ(RunTool("--sequence " + (dir / "nope").string() + " --out " + (dir / "x").string(), dir,
                    &out, &err),
            2);
  EXPECT_THAT(err, HasSubstr((dir / "nope").string() + ": no such directory"));
  EXPECT_EQ(RunTool("--sequence " + kSeq.string() + " --out " + (dir / "x").string() +
                        " --methods orbslam",
                    dir, &out, &err),
            2);
  EXPECT_THAT(err, HasSubstr("unknown method 'orbslam'"));
  fs::remove_all(dir);
}

}  // namespace
