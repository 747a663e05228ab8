// End-to-end tests of `ademono synth`: a small office and street sequence, and bad input (one-line
// error, exit code 2, no output folder or temporary folder left behind).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "ademono/io/sequence.h"
#include "ademono/perception/detection_io.h"
#include "cli_test_util.h"

namespace fs = std::filesystem;

namespace {

using ::testing::HasSubstr;

using RunResult = ademono::cli_test::CliRun;
using ademono::cli_test::ReadFile;

class SynthCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ademono::cli_test::FreshTempDir(
        std::string("synth_cli_") +
        ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  RunResult Run(const std::string& args) {
    return ademono::cli_test::RunAdemono("--log-level warn synth " + args, dir_);
  }
  // Entries of the test folder (the CLI must leave no temporary folders).
  std::vector<std::string> Entries() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }

  fs::path dir_;
};

TEST_F(SynthCliTest, OfficeSequenceLoadsAsTum) {
  const fs::path out = dir_ / "office";
  const RunResult r =
      Run("--scene office --motion rpy --frames 3 --seed 2 --width 160 --height 120 "
          "--noise 2 --blur 2 --persons 1 --out " +
          out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("wrote 3 frames of 'office'"));
  for (const char* name : {"rgb.txt", "depth.txt", "groundtruth.txt", "camera.yaml",
                           "detections.jsonl", "scene.json", "masks/0.066667.png"})
    EXPECT_TRUE(fs::exists(out / name)) << name;
  const auto sequence = ademono::OpenSequence("tum:" + out.string());
  EXPECT_EQ(sequence->Size(), 3u);
  EXPECT_EQ(sequence->GetCamera().width, 160);
  EXPECT_EQ(ademono::ReadDetectionsJsonl(out / "detections.jsonl").size(), 3u);
  EXPECT_EQ(Entries(), (std::vector<std::string>{"office"}));
}

TEST_F(SynthCliTest, StreetSequenceHasFullRangeDepth) {
  const fs::path out = dir_ / "street";
  const RunResult r =
      Run("--scene street --frames 1 --width 310 --height 94 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out / "depth_full" / "0.000000.tiff"));
  EXPECT_EQ(ademono::OpenSequence("tum:" + out.string())->Size(), 1u);
}

TEST_F(SynthCliTest, BadOptionsFailWithOneLineAndNoOutput) {
  const std::string out = (dir_ / "out").string();
  struct Case {
    std::string args, message;
  };
  for (const Case& c : std::vector<Case>{
           {"--scene moon",
            "ademono synth: error: invalid options: unknown scene 'moon' "
            "(expected office or street)\n"},
           {"--motion spin",
            "ademono synth: error: unknown motion 'spin' (expected xyz, "
            "halfsphere, rpy, static, forward or loop)\n"},
           {"--frames 0", "ademono synth: error: invalid options: frames must be in [1, 100000]\n"},
           {"--width 8",
            "ademono synth: error: invalid options: width and height must be in "
            "[16, 8192]\n"},
           {"--persons 4", "ademono synth: error: invalid options: persons must be 1, 2 or 3\n"},
           {"--blur -1",
            "ademono synth: error: invalid options: blur must be in [0, 100] pixels\n"},
       }) {
    const RunResult r = Run(c.args + " --out " + out);
    EXPECT_EQ(r.exit_code, 2) << c.args;
    EXPECT_EQ(r.err, c.message) << c.args;
    EXPECT_TRUE(Entries().empty()) << c.args;
  }
}

TEST_F(SynthCliTest, MissingActorPhotosFailWithOneLineAndNoOutput) {
  const fs::path missing = dir_ / "no_photos";
  const RunResult r = Run("--frames 1 --width 64 --height 48 --actor-photos " + missing.string() +
                          " --out " + (dir_ / "out").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "ademono synth: error: " + missing.string() +
                       ": actor photos folder not found (expected photos and "
                       "expected_detections.json, e.g. ../shared/images)\n");
  EXPECT_TRUE(Entries().empty());
  // A folder without the detections file names the file.
  fs::create_directories(missing);
  const RunResult r2 = Run("--frames 1 --width 64 --height 48 --actor-photos " +
                           missing.string() + " --out " + (dir_ / "out").string());
  EXPECT_EQ(r2.exit_code, 2);
  EXPECT_THAT(r2.err, HasSubstr("expected_detections.json"));
  EXPECT_EQ(std::count(r2.err.begin(), r2.err.end(), '\n'), 1);
  EXPECT_EQ(Entries(), (std::vector<std::string>{"no_photos"}));
}

TEST_F(SynthCliTest, RefusesNonEmptyOutputFolder) {
  fs::create_directories(dir_ / "out");
  std::ofstream(dir_ / "out" / "keep.txt") << "mine";
  const RunResult r = Run("--frames 1 --width 64 --height 48 --out " + (dir_ / "out").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("out: exists and is not empty"));
  EXPECT_EQ(Entries(), (std::vector<std::string>{"out"}));
  EXPECT_EQ(ReadFile(dir_ / "out" / "keep.txt"), "mine");
}

}  // namespace
