// KITTI end to end on the real frames in ../shared: `infer` with PyDNet caches depth, `run` from
// that cache knows the rig's camera height without a flag (and a config key overrides it),
// `ground` reads the camera's height from the cache frame by frame (under a run's poses too).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <Eigen/Geometry>
#include <fmt/format.h>
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
  EXPECT_TRUE(fs::exists(dir / "cache/depth/000011.tiff"));

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

// `ground --poses`: the two-view height is in the units of the motion it is given. The ground
// truth's own poses with every translation 1.1 times as long give a height 1.1 times the ground
// truth motion's on the same frames (the level fit in metres still starts the search, so units
// far from metres are out of its reach); a frame the file lacks has no estimate; a missing file
// is named.
TEST(KittiCliTest, GroundFromARunsPosesIsInThoseUnits) {
  const fs::path dir = FreshTempDir("kitti_ground_poses_cli");
  const std::string pydnet = "model:" + (kShared / "models/pydnet_kitti.onnx").string() +
                             ",spec=" + ADEMONO_SOURCE_DIR + "/configs/models/pydnet_kitti.yaml";
  std::ifstream times(kShared / "data/kitti-00/sequences/00/times.txt");
  std::ifstream poses(kShared / "data/kitti-00/poses/00.txt");
  std::ofstream tum(dir / "longer.tum");
  for (int i = 0; i <= 66; ++i) {
    double t = 0;
    Eigen::Matrix<double, 3, 4> rt;
    times >> t;
    for (int k = 0; k < 12; ++k) poses >> rt(k / 4, k % 4);
    ASSERT_TRUE(times && poses) << "frame " << i;
    if (i == 65) continue;  // a frame the run did not track
    const Eigen::Quaterniond q(Eigen::Matrix3d(rt.leftCols<3>()));
    const Eigen::Vector3d c = 1.1 * rt.col(3);
    tum << fmt::format("{:.9f} {:.9f} {:.9f} {:.9f} {:.12f} {:.12f} {:.12f} {:.12f}\n", t,
                           c.x(), c.y(), c.z(), q.x(), q.y(), q.z(), q.w());
  }
  tum.close();
  const std::string common = "ground --dataset " + kDataset + " --depth " + pydnet +
                             " --from two-view --gap 2 --frames 30:66 --every 35 --json ";
  CliResult r = RunCli(common + (dir / "gt.json").string());
  ASSERT_EQ(r.code, 0) << r.out;
  r = RunCli(common + (dir / "longer.json").string() + " --poses " +
             (dir / "longer.tum").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json gt = nlohmann::json::parse(ReadFile(dir / "gt.json"));
  const nlohmann::json longer = nlohmann::json::parse(ReadFile(dir / "longer.json"));
  ASSERT_EQ(gt["frames"].size(), 2u);  // frames 30 and 65
  ASSERT_EQ(longer["frames"].size(), 2u);
  ASSERT_TRUE(gt["frames"][0]["valid"].get<bool>());
  ASSERT_TRUE(longer["frames"][0]["valid"].get<bool>());
  EXPECT_NEAR(longer["frames"][0]["height_m"].get<double>() /
                  gt["frames"][0]["height_m"].get<double>(),
              1.1, 0.005);
  EXPECT_FALSE(longer["frames"][1]["valid"].get<bool>());  // no pose at frame 65
  EXPECT_TRUE(longer["frames"][1]["no_pose"].get<bool>());
  r = RunCli(common + (dir / "x.json").string() + " --poses " + (dir / "none.tum").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.out, testing::HasSubstr("none.tum"));
  EXPECT_FALSE(fs::exists(dir / "x.json"));
  fs::remove_all(dir);
}

// A drive at twice KITTI 00's speed (1.5 m a frame, as KITTI 04): every 2nd frame of the first
// 120, as symlinks with every 2nd ground-truth pose, PyDNet cached by `infer`, then the shipped
// command from the cache on four draws of the distant filter. With a keyframe's road counted
// from 50 points the map shrank for tens of frames before any road was measured: seeds 42 and
// 5 sim3 9.8 and 3.4 m, seed 1 se3 2.6 m at scale 1.10 (docs/kitti.md "Faster drives"; these
// are the draws that failed, chosen so that this test tells). Measured with 30: sim3
// 0.23-0.42 m, se3 0.40-0.82 m, scale 0.998-1.028 (millimetre caches). On exact depths (the
// float cache) PyDNet's depths beyond 65 m broke seeds 1 and 5 (se3 4.7 and 3.1 m, scale 0.86 and
// 1.12); with the spec's 65 m cut: sim3 0.17-0.22 m, se3 0.25-0.32 m, scale 1.004-1.008.
TEST(KittiCliTest, ADriveAtTwiceTheSpeedKeepsItsScale) {
  const fs::path dir = FreshTempDir("kitti_stride_cli");
  const fs::path source = kShared / "data/kitti-00";
  const fs::path sequence = dir / "sequences/00";
  fs::create_directories(sequence / "image_2");
  fs::create_directories(dir / "poses");
  fs::create_symlink(source / "sequences/00/calib.txt", sequence / "calib.txt");
  std::ifstream poses_in(source / "poses/00.txt");
  std::ofstream poses_out(dir / "poses/00.txt"), times(sequence / "times.txt");
  std::string pose;
  for (int frame = 0, kept = 0; frame < 120 && std::getline(poses_in, pose); ++frame) {
    if (frame % 2 != 0) continue;
    char from[16], to[16];
    std::snprintf(from, sizeof from, "%06d.jpg", frame);
    std::snprintf(to, sizeof to, "%06d.jpg", kept);
    fs::create_symlink(source / "sequences/00/image_2" / from, sequence / "image_2" / to);
    poses_out << pose << "\n";
    times << kept * 0.1 << "\n";
    ++kept;
  }
  poses_out.close();
  times.close();
  const std::string dataset = " --dataset kitti:" + sequence.string();
  const std::string model = (kShared / "models/pydnet_kitti.onnx").string() +
                            ",spec=" + ADEMONO_SOURCE_DIR + "/configs/models/pydnet_kitti.yaml";
  CliResult r = RunCli("infer" + dataset + " --depth-model model:" + model + " --out " +
                       (dir / "cache").string());
  ASSERT_EQ(r.code, 0) << r.out;
  for (const int seed : {42, 1, 2, 5}) {
    const fs::path out = dir / ("run" + std::to_string(seed));
    r = RunCli("run" + dataset + " --depth cache:" + (dir / "cache/depth").string() +
               ",model=" + model + " --seed " + std::to_string(seed) + " --out " + out.string());
    ASSERT_EQ(r.code, 0) << r.out;
    const nlohmann::json summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
    EXPECT_EQ(summary["tracked"].get<int>(), 60) << "seed " << seed;
    const nlohmann::json& accuracy = summary["accuracy"];
    EXPECT_LT(accuracy["ate_sim3_rmse_m"].get<double>(), 0.5) << "seed " << seed;
    EXPECT_LT(accuracy["ate_se3_rmse_m"].get<double>(), 1.0) << "seed " << seed;  // of 87 m
    EXPECT_NEAR(accuracy["sim3_scale"].get<double>(), 1.0, 0.05) << "seed " << seed;
    // The road gave the scale, and says how well it pinned it down.
    EXPECT_EQ(summary["metric_scale"]["source"], "ground") << "seed " << seed;
    const double sigma = summary["metric_scale"]["sigma"].get<double>();
    EXPECT_GT(sigma, 0.0) << "seed " << seed;
    EXPECT_LT(sigma, 0.02) << "seed " << seed;
    EXPECT_TRUE(summary["per_frame"][59].contains("scale_sigma")) << "seed " << seed;
  }
  fs::remove_all(dir);
}

}  // namespace
