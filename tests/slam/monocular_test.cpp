// The monocular core on the synthetic office (exact ground truth): without depth (geometry alone,
// a two-view start) against the same frames with exact depth, and with a simulated network whose
// every frame carries a known affine distortion in inverse depth, which the per-keyframe network
// error model must recover against the triangulated points.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "ademono/depth/simulated_depth.h"
#include "ademono/eval/trajectory_eval.h"
#include "ademono/slam/system.h"
#include "ademono/synth/generator.h"
#include "ademono/synth/scenes.h"
#include "simulated_network.h"

namespace ademono {
namespace {

enum class DepthInput { kNone, kExact, kNetwork };

struct OfficeRun {
  Trajectory estimate, truth;
  int tracked = 0;
  std::vector<std::pair<size_t, InverseDepthAffine>> fits;
};

synth::SceneOptions Office(size_t frames) {
  synth::SceneOptions scene_options;
  scene_options.scene = "office";
  scene_options.frames = frames;
  scene_options.seed = 5;
  scene_options.persons = 1;
  return scene_options;
}

SystemOptions Options(DepthInput input) {
  SystemOptions options = testing_util::SimulatedNetworkOptions();
  if (input == DepthInput::kExact) {
    options.depth.error_relative = 0;  // a sensor: depth is a measurement
    return options;
  }
  options.tracking.monocular = true;
  options.tracking.keyframe_ref_ratio = 0.9;
  options.mapping.handoff_frames = 4;
  options.mapping.cull_min_observations = 3;
  options.mapping.triangulation_neighbours = 20;
  options.mapping.triangulation_match_ratio = 0.8;
  if (input == DepthInput::kNone) options.depth.error_relative = 0;
  return options;
}

OfficeRun RunOffice(DepthInput input, size_t frames, const SimulatedDepthOptions& network) {
  const synth::SceneOptions scene_options = Office(frames);
  const synth::Scene scene = synth::BuildScene(scene_options);
  const SimulatedDepthProvider provider(network, nullptr);
  synth::GeneratorOptions generator;
  generator.scene = scene_options;
  System system(scene.camera, Options(input));
  OfficeRun run;
  for (size_t k = 0; k < frames; ++k) {
    const synth::RenderedFrame rendered = synth::RenderSceneFrame(scene, k, generator);
    FrameData frame;
    frame.index = k;
    frame.timestamp = scene.TimeOf(k);
    frame.image = rendered.image;
    cv::Mat depth;
    if (input == DepthInput::kExact) depth = rendered.depth;
    if (input == DepthInput::kNetwork) depth = provider.Degrade(rendered.depth, k);
    run.tracked += system.TrackFrame(frame, depth, {}).tracked;
    run.truth.push_back({frame.timestamp, scene.world_from_cam(frame.timestamp)});
  }
  system.Shutdown();
  run.estimate = system.FrameTrajectory();
  run.fits = system.NetworkFits();
  return run;
}

EvalResult Ate(const OfficeRun& run, Alignment alignment) {
  EvalOptions eval;
  eval.alignment = alignment;
  return EvaluateTrajectories(run.truth, run.estimate, eval);
}

TEST(MonocularTest, GeometryAloneIsWithinOneAndAHalfTimesExactDepth) {
  const size_t frames = 150;
  const OfficeRun exact = RunOffice(DepthInput::kExact, frames, {});
  const OfficeRun none = RunOffice(DepthInput::kNone, frames, {});
  // The two-view start waits for parallax; from there on every frame is tracked.
  ASSERT_GT(none.tracked, 0);
  EXPECT_GE(none.tracked, static_cast<int>(0.8 * frames));
  const double exact_sim3 = Ate(exact, Alignment::kSim3).ape.rmse;
  const double none_sim3 = Ate(none, Alignment::kSim3).ape.rmse;
  RecordProperty("exact_sim3_mm", static_cast<int>(exact_sim3 * 1000));
  RecordProperty("none_sim3_mm", static_cast<int>(none_sim3 * 1000));
  EXPECT_LE(none_sim3, 1.5 * exact_sim3) << "exact " << exact_sim3 << " none " << none_sim3;
}

TEST(MonocularTest, TheNetworksPerFrameAffineDistortionIsRecovered) {
  SimulatedDepthOptions network = testing_util::FastDepthLikeNetwork(60, 3);
  network.shift = 0.05;         // m^-1: the network compresses the depth range
  network.shift_jitter = 0.04;  // and by how much wanders from frame to frame
  const size_t frames = 150;
  const OfficeRun run = RunOffice(DepthInput::kNetwork, frames, network);
  ASSERT_GE(run.fits.size(), 5u);
  const SimulatedDepthProvider provider(network, nullptr);
  // The map's units against metres: 1 / z = s / z_map, so a_true = s a, b_true = s b.
  const double map_to_metric = Ate(run, Alignment::kSim3).gt_from_est.scale;
  int checked = 0, shift_ok = 0, scale_ok = 0;
  for (const auto& [index, fit] : run.fits) {
    if (fit.scale_only) continue;
    ++checked;
    const double true_scale = provider.FrameScale(index), true_shift = provider.FrameShift(index);
    // b / a = -shift whatever the map's scale.
    shift_ok += std::abs(-fit.b / fit.a - true_shift) < 0.03 ? 1 : 0;
    scale_ok += std::abs(std::log(fit.a * map_to_metric / true_scale)) < 0.05 ? 1 : 0;
  }
  ASSERT_GE(checked, 5);
  EXPECT_GE(shift_ok, 0.8 * checked) << shift_ok << " of " << checked;
  EXPECT_GE(scale_ok, 0.8 * checked) << scale_ok << " of " << checked;
}

}  // namespace
}  // namespace ademono
