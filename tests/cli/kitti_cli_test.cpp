// KITTI end to end on the real frames in ../shared: `infer` with PyDNet caches depth, `run` from
// that cache knows the rig's camera height without a flag (and a config key overrides it),
// `ground` reads the camera's height from the cache frame by frame.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_test_util.h"

namespace {

using namespace ademono::cli_test;
namespace fs = std::filesystem;
const fs::path kShared = ADEMONO_SHARED_DIR;
const std::string kDataset = "kitti:" + (kShared / "data/kitti-00/sequences/00").string();

TEST(KittiCliTest, InferRunAndGroundOnTheRealDrive) {
  const fs::path dir = FreshTempDir("kitti_cli");
  const std::string pydnet = "model:" + (kShared / "models/pydnet_kitti.onnx").string() +
                             ",spec=" + ADEMONO_SOURCE_DIR + "/configs/models/pydnet_kitti.yaml";
  CliResult r = RunCli("infer --dataset " + kDataset + " --frames 0:12 --depth-model " + pydnet +
                       " --out " + (dir / "cache").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_THAT(r.out, testing::HasSubstr("12 frames (0..11)"));
  EXPECT_TRUE(fs::exists(dir / "cache/depth/000011.png"));

  const std::string depth = " --depth cache:" + (dir / "cache/depth").string();
  r = RunCli("run --dataset " + kDataset + " --frames 0:12" + depth + " --out " +
             (dir / "run").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_THAT(r.out, testing::HasSubstr("depth.camera_height: 1.65 m, the kitti rig's"));
  YAML::Node resolved = YAML::LoadFile((dir / "run/config.resolved.yaml").string());
  EXPECT_EQ(resolved["depth"]["camera_height"].as<double>(), 1.65);
  // Another vehicle (or none): the config's key wins.
  r = RunCli("run --dataset " + kDataset + " --frames 0:12" + depth +
             " --set depth.camera_height=0 --out " + (dir / "run0").string());
  ASSERT_EQ(r.code, 0) << r.out;
  resolved = YAML::LoadFile((dir / "run0/config.resolved.yaml").string());
  EXPECT_EQ(resolved["depth"]["camera_height"].as<double>(), 0.0);

  r = RunCli("ground --dataset " + kDataset + depth + " --from level --every 4 --json " +
             (dir / "ground.json").string());
  // Frames 12.. have no cached depth: the cache names the frame it misses.
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_THAT(r.out, testing::HasSubstr("000012"));
  fs::remove_all(dir);
}

TEST(KittiCliTest, GroundPrintsEachFramesHeight) {
  const fs::path dir = FreshTempDir("kitti_ground_cli");
  const std::string pydnet = "model:" + (kShared / "models/pydnet_kitti.onnx").string() +
                             ",spec=" + ADEMONO_SOURCE_DIR + "/configs/models/pydnet_kitti.yaml";
  CliResult r = RunCli("ground --dataset " + kDataset + " --depth " + pydnet +
                       " --from two-view --gap 2 --frames 30:101 --every 35 "
                       "--reference-height 1.65 --json " + (dir / "ground.json").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(ReadFile(dir / "ground.json"));
  ASSERT_EQ(j["frames"].size(), 3u);  // frames 30, 65 and 100
  EXPECT_EQ(j["frames"][2]["frame"].get<int>(), 100);
  for (const auto& f : j["frames"]) {
    ASSERT_TRUE(f["valid"].get<bool>()) << f.dump();
    // Measured 1.575, 1.514, 1.631 m (the rig: 1.65 m).
    EXPECT_NEAR(f["height_m"].get<double>(), 1.65, 0.12 * 1.65) << f.dump();
  }
  EXPECT_THAT(r.out, testing::HasSubstr("median / reference 1.650 m"));
  r = RunCli("ground --dataset " + kDataset + " --depth " + pydnet + " --from sideways");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.out, testing::HasSubstr("--from 'sideways'"));
  fs::remove_all(dir);
}

}  // namespace
