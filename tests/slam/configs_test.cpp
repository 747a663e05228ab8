// Every dataset-family config in configs/ parses with the options' own checks, and its resolved
// options (ToYaml) read back to exactly the same values.
#include <unistd.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/core/options_table.h"
#include "ademono/slam/options.h"

namespace fs = std::filesystem;

namespace ademono {
namespace {

const fs::path kConfigDir = fs::path(ADEMONO_SOURCE_DIR) / "configs";

std::vector<fs::path> ShippedConfigs() {
  std::set<fs::path> sorted;
  for (const auto& entry : fs::directory_iterator(kConfigDir)) {
    if (entry.is_regular_file() && entry.path().extension() == ".yaml") sorted.insert(entry.path());
  }
  return {sorted.begin(), sorted.end()};
}

TEST(ConfigsTest, AllFamilyConfigsParse) {
  int count = 0;
  for (const char* name : {"tum_fr1.yaml", "tum_fr2.yaml", "tum_fr3.yaml", "kitti_00-02.yaml",
                           "kitti_03.yaml", "kitti_04-12.yaml", "euroc.yaml", "7scenes.yaml",
                           "rgbd_generic.yaml"}) {
    const fs::path path = kConfigDir / name;
    ASSERT_TRUE(fs::exists(path)) << path;
    EXPECT_NO_THROW(SystemOptions::FromYaml(YAML::LoadFile(path.string()), path)) << path;
    ++count;
  }
  EXPECT_EQ(count, 9);
  const SystemOptions kitti =
      SystemOptions::FromYaml(YAML::LoadFile((kConfigDir / "kitti_00-02.yaml").string()), "k");
  EXPECT_EQ(kitti.orb.num_features, 2000);
  EXPECT_NEAR(kitti.depth.CloseDepth(), 35 * 0.54, 1e-9);
}

// FromYaml(ToYaml(x)) == x for every shipped config, through the text of config.resolved.yaml.
TEST(ConfigsTest, ResolvedOptionsRoundTripForEveryShippedConfig) {
  const std::vector<fs::path> configs = ShippedConfigs();
  ASSERT_GE(configs.size(), 9u);  // tum x3, kitti x3, euroc, 7scenes, street
  for (const fs::path& path : configs) {
    SCOPED_TRACE(path.string());
    const YAML::Node root = YAML::LoadFile(path.string());
    const SystemOptions system = SystemOptions::FromYaml(root, path);
    const DetectorOptions detector = DetectorOptions::FromYaml(root["detector"]);
    const std::string text = ResolvedConfigText(system, detector);
    const YAML::Node resolved = YAML::Load(text);
    const SystemOptions system_back = SystemOptions::FromYaml(resolved, "resolved.yaml");
    EXPECT_TRUE(system_back == system);
    EXPECT_TRUE(DetectorOptions::FromYaml(resolved["detector"]) == detector);
    // Every key is written, so the resolved file alone says what the run used.
    EXPECT_EQ(resolved["filter"].size(), FilterOptions::Table().Keys().size());
    EXPECT_EQ(resolved["tracking"].size(), TrackingOptions::Table().Keys().size());
    EXPECT_EQ(ResolvedConfigText(system_back, detector), text);
  }
  // A changed value shows: the round trip is not comparing defaults with defaults.
  SystemOptions changed;
  changed.filter.seed = 7;
  changed.mapping.ba.second_iterations = 3;
  changed.depth.virtual_baseline = 0.1 + 0.2;
  const SystemOptions back =
      SystemOptions::FromYaml(YAML::Load(ResolvedConfigText(changed, {})), "r");
  EXPECT_EQ(back.filter.seed, 7u);
  EXPECT_EQ(back.mapping.ba.second_iterations, 3);
  EXPECT_EQ(back.depth.virtual_baseline, 0.1 + 0.2);
  EXPECT_FALSE(back == SystemOptions{});
}

TEST(ConfigsTest, WriteResolvedConfigWritesTheFileAtomically) {
  const fs::path dir =
      fs::temp_directory_path() / ("ademono_resolved_config_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const fs::path path = dir / "config.resolved.yaml";
  DetectorOptions detector;
  detector.score_threshold = 0.25f;
  WriteResolvedConfig(path, SystemOptions{}, detector);
  ASSERT_TRUE(fs::exists(path));
  EXPECT_EQ(ReadTextFile(path), ResolvedConfigText(SystemOptions{}, detector));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);  // no temp
  const YAML::Node node = YAML::LoadFile(path.string());
  EXPECT_EQ(DetectorOptions::FromYaml(node["detector"]).score_threshold, 0.25f);
  fs::remove_all(dir);
}

TEST(ConfigsTest, UnknownDetectorKeyIsAnInputErrorNamingFileAndKey) {
  const fs::path path = "/configs/bad.yaml";
  try {
    SystemOptions::FromYaml(YAML::Load("detector:\n  score_treshold: 0.5\n"), path);
    FAIL() << "unknown detector key accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "/configs/bad.yaml: unknown key 'detector.score_treshold'");
  }
  EXPECT_THROW(SystemOptions::FromYaml(YAML::Load("detector:\n  nms_iou: 0\n"), path), InputError);
  EXPECT_THROW(DetectorOptions::FromYaml(YAML::Load("{score_treshold: 0.5}")),
               std::invalid_argument);
  const DetectorOptions d =
      DetectorOptions::FromYaml(YAML::Load("{score_threshold: 0.5, class_ids: [0, 2]}"));
  EXPECT_EQ(d.score_threshold, 0.5f);
  EXPECT_EQ(d.class_ids, (std::vector<int>{0, 2}));
  EXPECT_EQ(d.nms_iou, DetectorOptions{}.nms_iou);
}

}  // namespace
}  // namespace ademono
