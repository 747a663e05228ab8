// `ademono run --save-map / --load-map [--localize-only]` and `ademono map info` on 7-Scenes:
// a map of frames 0-59, then frames 60-119 localised in it in a second process.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "cli_test_util.h"

namespace fs = std::filesystem;
using ademono::cli_test::CliResult;
using ademono::cli_test::ReadFile;
using ademono::cli_test::RunCli;

namespace {

std::string Dataset() {
  return std::string("7scenes:") + ADEMONO_SHARED_DIR + "/data/7scenes-seq-a";
}
std::string Config() { return std::string(ADEMONO_SOURCE_DIR) + "/configs/7scenes.yaml"; }

std::string Bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

class MapCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<fs::path>(fs::temp_directory_path() /
                                      ("ademono_map_cli_" + std::to_string(::getpid())));
    fs::remove_all(*dir_);
    fs::create_directories(*dir_);
    const CliResult r = RunCli("run --dataset " + Dataset() + " --config " + Config() +
                               " --frames 0:60 --save-map " + MapPath().string() + " --out " +
                               (*dir_ / "first").string());
    ASSERT_EQ(r.code, 0) << r.out;
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    dir_.reset();
  }
  static fs::path MapPath() { return *dir_ / "seq-a-0-60.map"; }
  static inline std::unique_ptr<fs::path> dir_;
};

TEST_F(MapCliTest, LocalizeOnlyTracksEveryFrameWithinTheBoundAndLeavesTheFile) {
  ASSERT_TRUE(fs::exists(MapPath()));
  const std::string before = Bytes(MapPath());
  const fs::path out = *dir_ / "second";
  const CliResult r = RunCli("run --dataset " + Dataset() + " --config " + Config() +
                             " --frames 60:120 --load-map " + MapPath().string() +
                             " --localize-only --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
  EXPECT_EQ(summary["frames"], 60);
  EXPECT_EQ(summary["tracked"], 60);
  EXPECT_LE(summary["accuracy"]["ate_se3_rmse_m"].get<double>(), 0.04);
  const auto first = nlohmann::json::parse(ReadFile(*dir_ / "first" / "summary.json"));
  // configs/7scenes.yaml localises with a temporary local map: its keyframes are counted beside
  // the loaded ones but never written; the map file stays as it was.
  EXPECT_GE(summary["keyframes"].get<int>(), first["keyframes"].get<int>());
  EXPECT_TRUE(Bytes(MapPath()) == before);
}

TEST_F(MapCliTest, MapInfoPrintsWhatTheMapHolds) {
  const CliResult r = RunCli("map info " + MapPath().string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("format version: 2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("camera: 640x480 fx 585"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("keyframes: "), std::string::npos);
  EXPECT_NE(r.out.find("map points: "), std::string::npos);
  EXPECT_NE(r.out.find("bounding box (m)"), std::string::npos);
  EXPECT_NE(r.out.find("scale: metric"), std::string::npos) << r.out;
}

// A map built with --depth none is in the units of its two-view start: `map info` says so; a run
// without depth uses it as it is, and a run with depth gives it metres: a depth sensor's at its
// first tracked frame, a network's long-run scale by the anchor.
TEST_F(MapCliTest, AMapWithoutMetricScaleTakesTheScaleOfTheDepth) {
  const fs::path none_map = *dir_ / "none.map";
  const CliResult built = RunCli("run --dataset " + Dataset() + " --depth none --frames 0:90" +
                                 " --save-map " + none_map.string() + " --out " +
                                 (*dir_ / "none_first").string());
  ASSERT_EQ(built.code, 0) << built.out;
  const CliResult info = RunCli("map info " + none_map.string());
  ASSERT_EQ(info.code, 0) << info.out;
  EXPECT_NE(info.out.find("scale: arbitrary (built with --depth none"), std::string::npos)
      << info.out;
  EXPECT_NE(info.out.find("bounding box (map units)"), std::string::npos) << info.out;

  // Sensor depth (7scenes.yaml takes it as a measurement): the first tracked frame, without its
  // depths, measures them against the map; from then on the map is in metres, so the run scores
  // as well aligned with se3 as with sim3 (each 0.01 m or so; se3 0.04 m while the map kept its
  // units, at 1.8x).
  const fs::path out = *dir_ / "none_with_depth";
  const CliResult r = RunCli("run --dataset " + Dataset() + " --config " + Config() +
                             " --frames 60:90 --load-map " + none_map.string() + " --out " +
                             out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find(none_map.string() + ": the map had no metric scale; the depth sensor gives it x"),
            std::string::npos)
      << r.out;
  const auto sensor = nlohmann::json::parse(ReadFile(out / "summary.json"));
  EXPECT_GE(sensor["tracked"].get<int>(), 25) << r.out;
  EXPECT_NEAR(sensor["accuracy"]["sim3_scale"].get<double>(), 1.0, 0.1) << r.out;

  const fs::path geometric = *dir_ / "none_without_depth";
  const CliResult g = RunCli("run --dataset " + Dataset() + " --depth none --frames 60:90" +
                             " --load-map " + none_map.string() + " --localize-only --out " +
                             geometric.string());
  ASSERT_EQ(g.code, 0) << g.out;
  const auto summary = nlohmann::json::parse(ReadFile(geometric / "summary.json"));
  EXPECT_GE(summary["tracked"].get<int>(), 25) << g.out;

  // A network's depth is a prior measured against the map frame by frame: the map takes its
  // long-run scale, so each frame's network-to-map ratio comes out near 1 (0.69 for every frame
  // while the map kept its two-view units).
  const fs::path network = *dir_ / "none_with_network";
  const CliResult n = RunCli("run --dataset " + Dataset() + " --depth model:" +
                             ADEMONO_SHARED_DIR + "/models/fastdepth_nyu_320.onnx" +
                             " --frames 60:90 --load-map " + none_map.string() + " --out " +
                             network.string());
  ASSERT_EQ(n.code, 0) << n.out;
  const auto with_network = nlohmann::json::parse(ReadFile(network / "summary.json"));
  EXPECT_GE(with_network["tracked"].get<int>(), 25) << n.out;
  EXPECT_NEAR(with_network["depth_scale"]["median"].get<double>(), 1.0, 0.1) << n.out;
}

TEST_F(MapCliTest, BadMapsExitTwoWithOneLineNamingTheFile) {
  const std::string good = Bytes(MapPath());
  std::string version = good, flipped = good;
  version[8] = 9;
  flipped[good.size() - 100] ^= 0x01;
  const fs::path camera = *dir_ / "camera.yaml";
  std::ofstream(camera) << "width: 640\nheight: 480\nfx: 600\nfy: 600\ncx: 320\ncy: 240\n";
  struct Case {
    std::string name, bytes, extra, needle;
  };
  const std::vector<Case> cases = {
      {"truncated", good.substr(0, good.size() - 1000), "", "truncated"},
      {"version", version, "", "version 9"},
      {"checksum", flipped, "", "checksum mismatch"},
      {"camera", good, " --camera " + camera.string(), "does not match the sequence"},
  };
  for (const Case& c : cases) {
    const fs::path bad = *dir_ / (c.name + ".map");
    std::ofstream(bad, std::ios::binary) << c.bytes;
    const fs::path out = *dir_ / ("out_" + c.name);
    const CliResult r = RunCli("run --dataset " + Dataset() + " --config " + Config() +
                               " --frames 60:62 --load-map " + bad.string() + c.extra +
                               " --localize-only --out " + out.string());
    EXPECT_EQ(r.code, 2) << c.name << ": " << r.out;
    EXPECT_NE(r.out.find(bad.string()), std::string::npos) << c.name << ": " << r.out;
    EXPECT_NE(r.out.find(c.needle), std::string::npos) << c.name << ": " << r.out;
    // One error line (the config lookup also logs an [info] line).
    size_t errors = 0;
    for (size_t at = r.out.find("error:"); at != std::string::npos;
         at = r.out.find("error:", at + 1))
      ++errors;
    EXPECT_EQ(errors, 1u) << c.name << ": " << r.out;
    EXPECT_FALSE(fs::exists(out)) << c.name << ": partial output";
    if (c.name != "camera") {
      const CliResult info = RunCli("map info " + bad.string());
      EXPECT_EQ(info.code, 2) << info.out;
      EXPECT_NE(info.out.find(c.needle), std::string::npos) << info.out;
    }
  }
  const CliResult r = RunCli("run --dataset " + Dataset() + " --frames 0:2 --localize-only --out " +
                             (*dir_ / "x").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--localize-only needs --load-map"), std::string::npos) << r.out;
}

}  // namespace
