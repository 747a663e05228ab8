#include <gtest/gtest.h>

#include <cmath>

#include "ademono/synth/camera_motion.h"
#include "ademono/synth/scenes.h"

namespace ademono::synth {
namespace {

// The loop motion is back at its start pose after one lap (85 % of the sequence) and far from it
// half a lap in, for both scenes.
TEST(LoopMotion, ComesBackToItsStartAfterOneLap) {
  for (const char* name : {"office", "street"}) {
    SceneOptions options;
    options.scene = name;
    options.motion = MotionKind::kLoop;
    options.frames = 200;
    options.width = 64;
    options.height = 48;
    const Scene scene = BuildScene(options);
    const double lap = 0.85 * 200 / scene.fps;
    const Rigid3d start = scene.world_from_cam(0.0);
    const Rigid3d back = scene.world_from_cam(lap);
    const Rigid3d half = scene.world_from_cam(lap / 2);
    // Only the seeded handheld jitter differs (a few mm / a fraction of a degree).
    EXPECT_LT((back.translation() - start.translation()).norm(), 0.05) << name;
    EXPECT_LT(Eigen::AngleAxisd(start.linear().transpose() * back.linear()).angle(), 0.02) << name;
    EXPECT_GT((half.translation() - start.translation()).norm(), 1.5) << name;
    // Half a lap later the camera looks the other way.
    EXPECT_LT(start.linear().col(2).dot(half.linear().col(2)), -0.5) << name;
  }
  EXPECT_EQ(ParseMotionKind("loop"), MotionKind::kLoop);
  EXPECT_EQ(MotionKindName(MotionKind::kLoop), "loop");
}

}  // namespace
}  // namespace ademono::synth
