// Loop closing on rendered sequences with exact ground truth: the office loop (one lap in 85 % of
// the sequence, then the first views again) with the simulated network's scale drift, closed and
// not closed; and sequences that never come back to a place, which must close no loop.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "ademono/depth/simulated_depth.h"
#include "ademono/eval/trajectory_eval.h"
#include "ademono/slam/system.h"
#include "ademono/synth/scenes.h"
#include "simulated_network.h"
#include "synthetic_run.h"

namespace ademono {
namespace {

struct LoopRun {
  std::vector<LoopEvent> loops;
  Trajectory estimate, truth;
  int tracked = 0;
  double ate_sim3 = 0;
};

SystemOptions NetworkOptions(bool loop) {
  SystemOptions options = testing_util::SimulatedNetworkOptions();
  options.loop.enabled = loop;
  return options;
}

LoopRun RunScene(const synth::SceneOptions& scene_options, const SystemOptions& options,
            uint64_t depth_seed) {
  const synth::Scene scene = synth::BuildScene(scene_options);
  const SimulatedDepthProvider network(testing_util::FastDepthLikeNetwork(200, depth_seed),
                                       nullptr);
  LoopRun run;
  System system(scene.camera, options);
  testing_util::SyntheticRun tracked =
      testing_util::TrackSyntheticScene(scene, scene_options, network, system);
  system.Shutdown();
  run.tracked = tracked.tracked;
  run.truth = std::move(tracked.truth);
  run.loops = system.Loops();
  run.estimate = system.FrameTrajectory();
  EvalOptions eval;
  eval.alignment = Alignment::kSim3;
  run.ate_sim3 = EvaluateTrajectories(run.truth, run.estimate, eval).ape.rmse;
  return run;
}

synth::SceneOptions OfficeLoop(size_t frames) {
  synth::SceneOptions o;
  o.scene = "office";
  o.motion = synth::MotionKind::kLoop;
  o.frames = frames;
  o.seed = 1;
  o.persons = 1;
  o.width = 320;
  o.height = 240;
  return o;
}

TEST(LoopClosingTest, OfficeLoopIsClosedAndReducesTheError) {
  const size_t frames = 240;
  SystemOptions on = NetworkOptions(true), off = NetworkOptions(false);
  on.tracking.static_test = off.tracking.static_test = false;
  const LoopRun closed = RunScene(OfficeLoop(frames), on, 3);
  const LoopRun open = RunScene(OfficeLoop(frames), off, 3);
  EXPECT_EQ(closed.tracked, static_cast<int>(frames));
  EXPECT_TRUE(open.loops.empty());
  ASSERT_FALSE(closed.loops.empty());
  const LoopEvent& loop = closed.loops.front();
  // The end of the lap (85 % of the frames) seen again at the start.
  EXPECT_GT(loop.query_frame, frames * 3 / 4);
  EXPECT_LT(loop.match_frame, frames / 8);
  EXPECT_TRUE(loop.sim3);  // network depth: its scale drifts
  EXPECT_GT(loop.correction_m, 0.0);
  EXPECT_GE(loop.matches, 40);
  // The geometric test off, as configs/network_indoor.yaml ships it for network depth. Measured
  // 0.228 -> 0.062 m (0.27x). With the test on the open lap is already better (0.062 m since the
  // test judges depth by its error model) and the closure gains less (0.057 m, 0.91x); the
  // 600-frame office and 300-frame street laps of tools/loop_acceptance.sh give 0.26x and 0.46x
  // (docs/loops.md).
  EXPECT_LE(closed.ate_sim3, 0.07) << "closed " << closed.ate_sim3 << " open " << open.ate_sim3;
  EXPECT_LE(closed.ate_sim3, 0.5 * open.ate_sim3)
      << "closed " << closed.ate_sim3 << " open " << open.ate_sim3;
}

TEST(LoopClosingTest, GlobalBundleAdjustmentAfterTheLoopIsMergedDeterministically) {
  // loop.global_ba: solved on its own thread from a snapshot, merged at a fixed keyframe. Two runs
  // give the same trajectory to the bit, and the lap is no worse than with the loop correction
  // alone.
  const size_t frames = 240;
  SystemOptions plain = NetworkOptions(true);
  plain.tracking.static_test = false;
  SystemOptions gba = plain;
  gba.loop.global_ba = true;
  const LoopRun first = RunScene(OfficeLoop(frames), gba, 3);
  const LoopRun second = RunScene(OfficeLoop(frames), gba, 3);
  const LoopRun without = RunScene(OfficeLoop(frames), plain, 3);
  ASSERT_FALSE(first.loops.empty());
  const LoopEvent& loop = first.loops.front();
  EXPECT_TRUE(loop.global_ba);
  EXPECT_TRUE(loop.global_ba_merged);
  EXPECT_GT(loop.global_ba_keyframes, 10u);
  EXPECT_GT(loop.global_ba_points, 1000u);
  // At a later keyframe's processing, or at the end (the last keyframe's id).
  EXPECT_GE(loop.global_ba_merged_at_keyframe, loop.query_keyframe);
  EXPECT_FALSE(without.loops.front().global_ba);
  ASSERT_EQ(first.estimate.size(), second.estimate.size());
  for (size_t i = 0; i < first.estimate.size(); ++i) {
    ASSERT_EQ(first.estimate[i].timestamp, second.estimate[i].timestamp);
    ASSERT_TRUE(first.estimate[i].world_from_cam.matrix() ==
                second.estimate[i].world_from_cam.matrix())
        << "frame " << i;
  }
  EXPECT_EQ(first.ate_sim3, second.ate_sim3);
  EXPECT_LE(first.ate_sim3, without.ate_sim3 + 0.005)
      << "global BA " << first.ate_sim3 << " loop correction alone " << without.ate_sim3;
}

TEST(LoopClosingTest, NoLoopWithoutARevisit) {
  // Forward through the office (never back) and the street driving on: no place is seen twice.
  synth::SceneOptions office;
  office.scene = "office";
  office.motion = synth::MotionKind::kForward;
  office.frames = 80;
  office.seed = 2;
  office.persons = 1;
  office.width = 320;
  office.height = 240;
  const LoopRun run = RunScene(office, NetworkOptions(true), 4);
  EXPECT_GT(run.tracked, 70);
  EXPECT_TRUE(run.loops.empty());
}

}  // namespace
}  // namespace ademono
