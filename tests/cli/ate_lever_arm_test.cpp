// tools/ate_lever_arm.py on an exact oracle: a ground truth made from the estimate by a known
// sim3 and a known offset in the ground truth's body frame. The tool must recover the offset and
// leave no error; without an offset it must fit none. Bad input exits 2 with one line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace {

using ::testing::HasSubstr;

const fs::path kTool = fs::path(ADEMONO_SOURCE_DIR) / "tools" / "ate_lever_arm.py";

bool HaveNumpy() { return std::system("/usr/bin/python3 -c 'import numpy' >/dev/null 2>&1") == 0; }

std::string Read(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int RunTool(const std::string& args, const fs::path& dir, std::string* out, std::string* err) {
  const std::string cmd = "/usr/bin/python3 " + kTool.string() + " " + args + " >" +
                          (dir / "o.txt").string() + " 2>" + (dir / "e.txt").string();
  const int status = std::system(cmd.c_str());
  *out = Read(dir / "o.txt");
  *err = Read(dir / "e.txt");
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
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
  const fs::path dir = fs::temp_directory_path() / ("ademono_lever_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  WriteRun(dir / "offset", Eigen::Vector3d(0.02, 0.10, -0.07));
  WriteRun(dir / "exact", Eigen::Vector3d::Zero());
  std::string out, err;
  ASSERT_EQ(RunTool((dir / "offset").string() + " " + (dir / "exact").string(), dir, &out, &err), 0)
      << err;
  const std::vector<double> offset = Row(out, dir / "offset");
  ASSERT_EQ(offset.size(), 6u) << out;
  EXPECT_GT(offset[0], 0.01);  // a sim3 alone cannot take out an offset that turns
  EXPECT_LT(offset[1], 1e-3);  // printed to 4 decimals
  EXPECT_NEAR(offset[2], 0.02, 1e-3);
  EXPECT_NEAR(offset[3], 0.10, 1e-3);
  EXPECT_NEAR(offset[4], -0.07, 1e-3);
  const std::vector<double> exact = Row(out, dir / "exact");
  ASSERT_EQ(exact.size(), 6u) << out;
  EXPECT_LT(exact[0], 1e-3);
  EXPECT_LT(exact[5], 1e-3);

  // A missing run folder: exit 2, one line naming the file, no table.
  EXPECT_EQ(RunTool((dir / "offset").string() + " " + (dir / "missing").string(), dir, &out, &err),
            2);
  EXPECT_THAT(err, HasSubstr((dir / "missing" / "trajectory.tum").string()));
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1);
  EXPECT_EQ(out, "");
  // A malformed line.
  std::ofstream(dir / "offset" / "groundtruth.tum", std::ios::app) << "1.0 2.0 oops\n";
  EXPECT_EQ(RunTool((dir / "offset").string(), dir, &out, &err), 2);
  EXPECT_THAT(err, HasSubstr("groundtruth.tum: line 201: expected 8 columns"));
  EXPECT_EQ(out, "");
  fs::remove_all(dir);
}

}  // namespace
