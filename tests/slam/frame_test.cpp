#include "ademono/slam/frame.h"

#include <gtest/gtest.h>

#include "frame_test_util.h"

namespace ademono {
namespace {

using testing_util::TestFeatures;

TEST(FrameFeaturesTest, GridSearchAndVirtualRightCoordinate) {
  const auto f =
      TestFeatures({{100, 100}, {105, 102}, {300, 200}, {639, 479}}, {1.0f, -1.f, 2.0f, 0.f}, 1);
  EXPECT_EQ(f->FeaturesInArea(102, 101, 10), (std::vector<size_t>{0, 1}));
  EXPECT_EQ(f->FeaturesInArea(300, 200, 2), (std::vector<size_t>{2}));
  EXPECT_TRUE(f->FeaturesInArea(300, 200, 2, 1, 3).empty());  // all on level 0
  EXPECT_EQ(f->FeaturesInArea(638, 478, 4), (std::vector<size_t>{3}));
  EXPECT_NEAR(f->u_right[0], 100 - 585 * 0.08 / 1.0, 1e-3);
  EXPECT_LT(f->u_right[1], 0);
  EXPECT_LT(f->u_right[3], 0);
  EXPECT_TRUE(f->IsClose(0));
  EXPECT_FALSE(f->IsClose(1));
  const Eigen::Vector3d p = f->UnprojectCamera(2);
  EXPECT_NEAR(p.z(), 2.0, 1e-9);
  EXPECT_NEAR(p.x(), (300 - 320) * 2.0 / 585, 1e-9);
}

}  // namespace
}  // namespace ademono
