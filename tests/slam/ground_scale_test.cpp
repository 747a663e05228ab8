// depth.camera_height: a network's constant scale bias made observable by the known height of a
// vehicle's camera above the road. The synthetic street (camera 1.65 m above the road, 10 m/s)
// with the simulated network reading every depth 8 % long: without the ground the map is 8 %
// too large; with it the map is metric, on both depth paths (a fixed scale without an error
// model, as configs/street.yaml; the per-frame correction anchored to the ground with one).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>
#include <vector>

#include "ademono/core/statistics.h"
#include "ademono/depth/simulated_depth.h"
#include "ademono/eval/trajectory_eval.h"
#include "ademono/optimize/bundle_adjustment.h"
#include "ademono/slam/system.h"
#include "ademono/synth/scenes.h"
#include "synthetic_run.h"

namespace ademono {
namespace {

constexpr double kNetworkScale = 1.08;
constexpr double kCameraHeight = 1.65;  // synth's street

struct StreetRun {
  int tracked = 0;
  double sim3_scale = 0;  // truth = sim3_scale * estimate
  double ate_se3 = 0;
  std::vector<double> ground_heights;
};

StreetRun RunStreet(double camera_height, bool error_model,
                    const std::string& config = "street.yaml", size_t frames = 40,
                    bool global_ba_at_end = false) {
  synth::SceneOptions scene_options;
  scene_options.scene = "street";
  scene_options.frames = frames;
  scene_options.seed = 2;
  const synth::Scene scene = synth::BuildScene(scene_options);
  SimulatedDepthOptions network;
  network.scale = kNetworkScale;
  network.seed = 2;
  const SimulatedDepthProvider depth(network, nullptr);

  const std::string path = std::string(ADEMONO_SOURCE_DIR) + "/configs/" + config;
  SystemOptions options = SystemOptions::FromYaml(YAML::LoadFile(path), path);
  options.depth.camera_height = camera_height;
  options.loop.global_ba_at_end = global_ba_at_end;
  if (error_model) {
    options.depth.error_relative = network.a;
    options.depth.error_per_metre = network.b;
  }
  System system(scene.camera, options);
  const testing_util::SyntheticRun tracked =
      testing_util::TrackSyntheticScene(scene, scene_options, depth, system);
  system.Shutdown();
  StreetRun run;
  run.tracked = tracked.tracked;
  const Trajectory& truth = tracked.truth;
  run.ground_heights = system.GroundHeights();
  EvalOptions eval;
  eval.alignment = Alignment::kSim3;
  run.sim3_scale = EvaluateTrajectories(truth, system.FrameTrajectory(), eval).gt_from_est.scale;
  eval.alignment = Alignment::kSe3;
  run.ate_se3 = EvaluateTrajectories(truth, system.FrameTrajectory(), eval).ape.rmse;
  return run;
}

TEST(GroundScaleTest, KnownCameraHeightUndoesTheNetworksScaleBias) {
  const StreetRun off = RunStreet(0, false);
  EXPECT_EQ(off.tracked, 40);
  EXPECT_TRUE(off.ground_heights.empty());
  EXPECT_NEAR(off.sim3_scale * kNetworkScale, 1.0, 0.01);  // the map is the network's size

  const StreetRun on = RunStreet(kCameraHeight, false);
  EXPECT_EQ(on.tracked, 40);
  // Measured at initialisation and at (nearly) every keyframe; in the final map's units.
  EXPECT_GE(on.ground_heights.size(), 10u);
  EXPECT_NEAR(Median(on.ground_heights), kCameraHeight, 0.01 * kCameraHeight);
  EXPECT_NEAR(on.sim3_scale, 1.0, 0.01);
  EXPECT_LT(on.ate_se3, 0.5 * off.ate_se3);
  RecordProperty("ate_se3_off_mm", static_cast<int>(1000 * off.ate_se3));
  RecordProperty("ate_se3_on_mm", static_cast<int>(1000 * on.ate_se3));
}

TEST(GroundScaleTest, PerFrameCorrectionIsAnchoredToTheGround) {
  // With the error model on, the map follows the network's mean correction unless the ground
  // anchors it.
  const StreetRun on = RunStreet(kCameraHeight, true);
  EXPECT_EQ(on.tracked, 40);
  EXPECT_GE(on.ground_heights.size(), 10u);
  EXPECT_NEAR(on.sim3_scale, 1.0, 0.015);
}

TEST(GroundScaleTest, GlobalBundleAdjustmentHoldsTheRoadAsLocalBaDoes) {
  // The monocular core outdoors (network_outdoor.yaml): local BA holds each keyframe's road
  // points at the rig's height (depth.ground_in_ba). A global BA over the whole map (after a
  // loop, before a save, at the end) must hold the same road, or it lets the scale drift back
  // (KITTI 00 with PyDNet: sim3 0.38 -> 0.89 m without the road, 0.45 m with it).
  // Called on the mapping and global-BA threads; read here after the run joined them. The
  // end's global BA is the last problem solved: every keyframe, only the first one fixed.
  size_t cameras = 0, fixed = 0, road_terms = 0;
  SetBundleAdjustmentObserver([&](const BundleAdjustmentProblem& problem) {
    cameras = problem.cameras.size();
    fixed = 0;
    for (const BaCamera& c : problem.cameras) fixed += c.fixed ? 1 : 0;
    road_terms = problem.plane_distances.size();
  });
  const StreetRun local = RunStreet(kCameraHeight, false, "network_outdoor.yaml", 60, false);
  const StreetRun global = RunStreet(kCameraHeight, false, "network_outdoor.yaml", 60, true);
  SetBundleAdjustmentObserver(nullptr);
  EXPECT_EQ(global.tracked, 60);
  EXPECT_GE(cameras, 10u);
  EXPECT_EQ(fixed, 1u);
  EXPECT_GT(road_terms, 10u * cameras);  // the road's points, at every keyframe
  // The whole-map solve keeps the scale local BA reached (measured 0.97376 and 0.97428).
  EXPECT_NEAR(global.sim3_scale, local.sim3_scale, 0.005);
  // Within 2 % with a keyframe's road from 50 points; from 30 (network_outdoor.yaml since
  // 67a8320: faster KITTI drives) these 60 street frames read 2.6 % short, while the street's
  // 150 frames read 0.987 either way (README, the monocular table).
  EXPECT_NEAR(local.sim3_scale, 1.0, 0.03);
  EXPECT_NEAR(global.sim3_scale, 1.0, 0.03);
  RecordProperty("sim3_scale_local_x1000", static_cast<int>(1000 * local.sim3_scale));
  RecordProperty("sim3_scale_global_x1000", static_cast<int>(1000 * global.sim3_scale));
}

}  // namespace
}  // namespace ademono
