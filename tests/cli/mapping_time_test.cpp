// tools/mapping_time.py on real debug logs: a seq-a window run with sensor depth and without
// depth. Each column's keyframes are the run's keyframe lines, the monocular core's local BA
// is the larger problem, and bad input exits 1 with one message naming the file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "cli_test_util.h"

namespace fs = std::filesystem;

namespace {

namespace cli_test = ademono::cli_test;
using ::testing::HasSubstr;

const fs::path kSeq = fs::path(ADEMONO_SHARED_DIR) / "data" / "7scenes-seq-a";
const fs::path kTool = fs::path(ADEMONO_SOURCE_DIR) / "tools" / "mapping_time.py";

// The table's row `name`, one number per column.
std::vector<double> Row(const std::string& table, const std::string& name) {
  std::vector<double> values;
  std::istringstream lines(table);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("| " + name + " |", 0) != 0) continue;
    std::istringstream cells(line.substr(name.size() + 4));
    std::string cell;
    while (std::getline(cells, cell, '|')) {
      if (cell.find_first_not_of(' ') != std::string::npos) values.push_back(std::stod(cell));
    }
  }
  return values;
}

TEST(MappingTimeTest, SumsTheKeyFramesOfSensorAndGeometricRuns) {
  if (!fs::exists(kSeq)) GTEST_SKIP() << "no 7-Scenes data";
  const fs::path dir = cli_test::FreshTempDir("mt");
  for (const std::string depth : {"sensor", "none"}) {
    const cli_test::CliRun run = cli_test::RunAdemono(
        "--log-level debug run --dataset 7scenes:" + kSeq.string() + " --frames 0:150 --depth " +
            depth + " --out " + (dir / depth).string(),
        dir);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    std::ofstream(dir / (depth + ".log")) << run.out << run.err;
  }
  const std::string tool = "/usr/bin/python3 " + kTool.string() + " ";
  const cli_test::CliRun mapping_time = cli_test::RunCommand(
      tool + (dir / "sensor.log").string() + " " + (dir / "none.log").string(), dir);
  ASSERT_EQ(mapping_time.exit_code, 0) << mapping_time.err;
  const std::string& table = mapping_time.out;
  const std::vector<double> keyframes = Row(table, "keyframes");
  ASSERT_EQ(keyframes.size(), 2u) << table;
  for (int k = 0; k < 2; ++k) {
    const std::string log = cli_test::ReadFile(dir / (k == 0 ? "sensor.log" : "none.log"));
    const std::regex line("keyframe \\d+: structure");
    const auto n =
        std::distance(std::sregex_iterator(log.begin(), log.end(), line), std::sregex_iterator());
    EXPECT_EQ(keyframes[k], static_cast<double>(n));
    EXPECT_GT(keyframes[k], 2);
  }
  // Triangulated structure: the monocular window has more observations per local BA.
  const std::vector<double> observations = Row(table, "BA observations (mean)");
  ASSERT_EQ(observations.size(), 2u);
  EXPECT_GT(observations[1], observations[0]);
  const std::vector<double> total = Row(table, "tracking thread in all");
  const std::vector<double> structure = Row(table, "structure");
  ASSERT_EQ(total.size(), 2u);
  ASSERT_EQ(structure.size(), 2u);
  EXPECT_GE(total[1], structure[1]);
  EXPECT_GT(structure[1], 0);

  const cli_test::CliRun missing = cli_test::RunCommand(tool + (dir / "nope.log").string(), dir);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_THAT(missing.err, HasSubstr((dir / "nope.log").string() + ": No such file"));
  std::ofstream(dir / "empty.log") << "[info] nothing\n";
  const cli_test::CliRun empty = cli_test::RunCommand(tool + (dir / "empty.log").string(), dir);
  EXPECT_EQ(empty.exit_code, 1);
  EXPECT_THAT(empty.err, HasSubstr("empty.log: no keyframe lines"));
  fs::remove_all(dir);
}

}  // namespace
