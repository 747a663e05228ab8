// Every dataset-family config in configs/ parses with the options' own checks.
#include <gtest/gtest.h>

#include <filesystem>

#include "ademono/slam/options.h"

namespace ademono {
namespace {

TEST(ConfigsTest, AllFamilyConfigsParse) {
  const std::filesystem::path dir = std::filesystem::path(ADEMONO_SOURCE_DIR) / "configs";
  int count = 0;
  for (const char* name : {"tum_fr1.yaml", "tum_fr2.yaml", "tum_fr3.yaml", "kitti_00-02.yaml",
                           "kitti_03.yaml", "kitti_04-12.yaml", "euroc.yaml", "7scenes.yaml"}) {
    const std::filesystem::path path = dir / name;
    ASSERT_TRUE(std::filesystem::exists(path)) << path;
    EXPECT_NO_THROW(SystemOptions::FromYaml(YAML::LoadFile(path.string()), path)) << path;
    ++count;
  }
  EXPECT_EQ(count, 8);
  const SystemOptions kitti =
      SystemOptions::FromYaml(YAML::LoadFile((dir / "kitti_00-02.yaml").string()), "k");
  EXPECT_EQ(kitti.orb.num_features, 2000);
  EXPECT_NEAR(kitti.depth.CloseDepth(), 35 * 0.54, 1e-9);
}

}  // namespace
}  // namespace ademono
