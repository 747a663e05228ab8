// tools/ate_lever_arm.py on an exact oracle: a ground truth made from the estimate by a known
// sim3 and a known offset in the ground truth's body frame. The tool must recover the offset and
// leave no error; without an offset it must fit none. Bad input exits 2 with one line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "cli_test_util.h"

namespace fs = std::filesystem;

namespace {

using ademono::cli_test::CliRun;
using ademono::cli_test::FreshTempDir;
using ademono::cli_test::RunCommand;
using ::testing::HasSubstr;

const fs::path kTool = fs::path(ADEMONO_SOURCE_DIR) / "tools" / "ate_lever_arm.py";

bool HaveNumpy() { return std::system("/usr/bin/python3 -c 'import numpy' >/dev/null 2>&1") == 0; }

CliRun RunTool(const std::string& args, const fs::path& dir) {
  return RunCommand("/usr/bin/python3 " + kTool.string() + " " + args, dir);
}

void WriteTum(std::ofstream& out, int i, const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  out << std::setprecision(17) << i * 0.1 << " " << p.x() << " " << p.y() << " " << p.z() << " "
      << q.x() << " " << q.y() << " " << q.z() << " " << q.w() << "\n";
}

// A run folder whose ground truth is s * A * p + t + R_gt * lever, with R_gt = A * R_est.
void WriteRun(const fs::path& run, const Eigen::Vector3d& lever) {
  fs::create_directories(run);
  std::ofstream est(run / "trajectory.tum"), gt(run / "groundtruth.tum");
  const double s = 1.7;
  const Eigen::Matrix3d a = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  const Eigen::Vector3d t(0.3, -1.2, 2.0);
  for (int i = 0; i < 200; ++i) {
    const double u = 0.05 * i;
    const Eigen::Vector3d p(std::sin(u), 0.3 * std::cos(1.3 * u), 0.1 * u);
    // The camera turns about all three axes, so an offset is observable.
    const Eigen::Matrix3d r =
        (Eigen::AngleAxisd(0.8 * std::sin(u), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(0.5 * std::cos(0.7 * u), Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(0.3 * std::sin(1.9 * u), Eigen::Vector3d::UnitZ()))
            .matrix();
    const Eigen::Matrix3d r_gt = a * r;
    WriteTum(est, i, p, Eigen::Quaterniond(r));
    WriteTum(gt, i, s * a * p + t + r_gt * lever, Eigen::Quaterniond(r_gt));
  }
}

// The numbers of the table row that names `run`: ATE sim3, with lever arm, lx, ly, lz, |l|.
std::vector<double> Row(const std::string& out, const fs::path& run) {
  std::istringstream lines(out);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("| " + run.string() + " |", 0) != 0) continue;
    for (char& c : line)
      if (c == '|' || c == '(' || c == ')' || c == ',') c = ' ';
    std::istringstream ss(line.substr(run.string().size() + 2));
    std::vector<double> v;
    double x;
    while (ss >> x) v.push_back(x);
    return std::vector<double>(v.begin() + 1, v.end());  // without the pose count
  }
  return {};
}

TEST(AteLeverArmTest, RecoversAKnownOffsetAndFitsNoneWhereThereIsNone) {
  if (!HaveNumpy()) GTEST_SKIP() << "no numpy";
  const fs::path dir = FreshTempDir("lever");
  WriteRun(dir / "offset", Eigen::Vector3d(0.02, 0.10, -0.07));
  WriteRun(dir / "exact", Eigen::Vector3d::Zero());
  CliRun run = RunTool((dir / "offset").string() + " " + (dir / "exact").string(), dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::vector<double> offset = Row(run.out, dir / "offset");
  ASSERT_EQ(offset.size(), 6u) << run.out;
  EXPECT_GT(offset[0], 0.01);  // a sim3 alone cannot take out an offset that turns
  EXPECT_LT(offset[1], 1e-3);  // printed to 4 decimals
  EXPECT_NEAR(offset[2], 0.02, 1e-3);
  EXPECT_NEAR(offset[3], 0.10, 1e-3);
  EXPECT_NEAR(offset[4], -0.07, 1e-3);
  const std::vector<double> exact = Row(run.out, dir / "exact");
  ASSERT_EQ(exact.size(), 6u) << run.out;
  EXPECT_LT(exact[0], 1e-3);
  EXPECT_LT(exact[5], 1e-3);

  // A missing run folder: exit 2, one line naming the file, no table.
  run = RunTool((dir / "offset").string() + " " + (dir / "missing").string(), dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr((dir / "missing" / "trajectory.tum").string()));
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1);
  EXPECT_EQ(run.out, "");
  // A malformed line.
  std::ofstream(dir / "offset" / "groundtruth.tum", std::ios::app) << "1.0 2.0 oops\n";
  run = RunTool((dir / "offset").string(), dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("groundtruth.tum: line 201: expected 8 columns"));
  EXPECT_EQ(run.out, "");
  fs::remove_all(dir);
}

}  // namespace
