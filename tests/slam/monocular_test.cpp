// The monocular core on the synthetic office (exact ground truth): without depth (geometry alone,
// a two-view start) against the same frames with exact depth, and with a simulated network whose
// every frame carries a known affine distortion in inverse depth, which the per-keyframe network
// error model must recover against the triangulated points.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "ademono/core/error.h"
#include "ademono/depth/simulated_depth.h"
#include "ademono/eval/trajectory_eval.h"
#include "ademono/slam/map_io.h"
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
  int keyframes_made = 0;  // by tracking, before culling
  int scale_sigmas = 0;    // frames that reported a metric-scale sigma
  std::optional<double> last_scale_sigma;
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
  options.tracking.interpolate_trajectory = true;  // as network_indoor.yaml
  options.mapping.triangulation_depth_sigmas = 0;  // as network_indoor.yaml
  if (input == DepthInput::kNone) options.depth.error_relative = 0;
  return options;
}

// `first_index`: the number of the run's first frame (a run need not start at frame 0);
// `scale_prior`: each keyframe's network scale held in local BA (on, as network_indoor.yaml).
OfficeRun RunOffice(DepthInput input, size_t frames, const SimulatedDepthOptions& network,
                    size_t first_index = 0, bool scale_prior = true,
                    bool parallax_baseline = true) {
  const synth::SceneOptions scene_options = Office(frames);
  const synth::Scene scene = synth::BuildScene(scene_options);
  const SimulatedDepthProvider provider(network, nullptr);
  synth::GeneratorOptions generator;
  generator.scene = scene_options;
  SystemOptions options = Options(input);
  options.mapping.network_scale_prior = scale_prior;
  options.tracking.keyframe_parallax_baseline = parallax_baseline;
  System system(scene.camera, options);
  OfficeRun run;
  for (size_t k = 0; k < frames; ++k) {
    const synth::RenderedFrame rendered = synth::RenderSceneFrame(scene, k, generator);
    FrameData frame;
    frame.index = first_index + k;
    frame.timestamp = scene.TimeOf(k);
    frame.image = rendered.image;
    cv::Mat depth;
    if (input == DepthInput::kExact) depth = rendered.depth;
    if (input == DepthInput::kNetwork) depth = provider.Degrade(rendered.depth, k);
    const TrackResult result = system.TrackFrame(frame, depth, {});
    run.tracked += result.tracked;
    run.keyframes_made += result.new_keyframe;
    if (result.scale_sigma) {
      ++run.scale_sigmas;
      run.last_scale_sigma = result.scale_sigma;
    }
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

// The frames of `run` whose timestamps `reference` also has: both scored on the same frames.
OfficeRun OnFramesOf(const OfficeRun& run, const OfficeRun& reference) {
  OfficeRun out = run;
  out.estimate.clear();
  for (const auto& stamped : run.estimate) {
    for (const auto& other : reference.estimate) {
      if (std::abs(other.timestamp - stamped.timestamp) < 1e-6) {
        out.estimate.push_back(stamped);
        break;
      }
    }
  }
  return out;
}

TEST(MonocularTest, GeometryAloneIsWithinTwiceExactDepth) {
  const size_t frames = 150;
  const OfficeRun exact = RunOffice(DepthInput::kExact, frames, {});
  const OfficeRun none = RunOffice(DepthInput::kNone, frames, {});
  // The two-view start waits for parallax; from there on every frame is tracked.
  ASSERT_GT(none.tracked, 0);
  ASSERT_FALSE(none.estimate.empty());
  const double first = none.estimate.front().timestamp;
  size_t after_init = 0;
  for (const auto& stamped : none.truth) after_init += stamped.timestamp >= first - 1e-6 ? 1 : 0;
  EXPECT_GE(none.tracked, static_cast<int>(0.95 * after_init)) << after_init << " after init";
  EXPECT_LE(after_init, 0.7 * frames) << "initialised late";
  // Scored on the frames both tracked: geometry has no depth, so it starts later.
  const double exact_sim3 = Ate(OnFramesOf(exact, none), Alignment::kSim3).ape.rmse;
  const double none_sim3 = Ate(none, Alignment::kSim3).ape.rmse;
  RecordProperty("exact_sim3_um", static_cast<int>(exact_sim3 * 1e6));
  RecordProperty("none_sim3_um", static_cast<int>(none_sim3 * 1e6));
  // Measured: 4.5 mm against 2.7 mm (1.67x; issue 28 asks 1.5x, which the acceptance table's
  // office with walking persons meets: 0.93x, tests/cli/geometric_cli_test.cpp), and 7.6 mm
  // before frames followed the keyframes around them (tracking.interpolate_trajectory). Without
  // depth the map's scale drifts, which one sim3 scale cannot take out; with depth every frame
  // measures it.
  EXPECT_LE(none_sim3, 2.0 * exact_sim3) << "exact " << exact_sim3 << " none " << none_sim3;
  EXPECT_LE(none_sim3, 0.01) << "metres, at the sim3 scale";

  // Local mapping's hand-off clock counts tracked frames, whatever they are numbered: a run that
  // starts at frame 1000 (`--frames 1000:`, a camera's counter) is the run that starts at 0.
  // When a keyframe's hand-off frame came from the dataset index, a run that did not start at 0
  // never merged a keyframe before the next one, so local mapping was never idle and a monocular
  // run made keyframes only every `max_frames_between_keyframes` (seq-a frames 250-599: 9
  // keyframes instead of 41, sim3 0.037 m instead of 0.027 m).
  const OfficeRun from_thousand = RunOffice(DepthInput::kNone, frames, {}, 1000);
  EXPECT_EQ(from_thousand.tracked, none.tracked);
  ASSERT_EQ(from_thousand.estimate.size(), none.estimate.size());
  for (size_t i = 0; i < none.estimate.size(); ++i) {
    EXPECT_EQ(from_thousand.estimate[i].world_from_cam.matrix(),
              none.estimate[i].world_from_cam.matrix())
        << "frame at " << none.estimate[i].timestamp;
  }
}

// tracking.keyframe_parallax_baseline: a monocular keyframe comes only once its baseline to the
// reference keyframe gives a point at the median depth the parallax a new point is triangulated
// with (1 degree), not at ORB-SLAM's 1 % of the depth (a quarter of that), where it adds views
// but no structure of its own. Fewer keyframes, the same shape.
TEST(MonocularTest, KeyFramesWaitForTheBaselineNewPointsNeed) {
  const size_t frames = 150;
  const OfficeRun gated = RunOffice(DepthInput::kNone, frames, {}, 0, false, true);
  const OfficeRun ungated = RunOffice(DepthInput::kNone, frames, {}, 0, false, false);
  ASSERT_GT(ungated.keyframes_made, 0);
  RecordProperty("keyframes_gated", gated.keyframes_made);
  RecordProperty("keyframes_ungated", ungated.keyframes_made);
  EXPECT_LE(gated.keyframes_made, 0.9 * ungated.keyframes_made)
      << gated.keyframes_made << " against " << ungated.keyframes_made;
  EXPECT_EQ(gated.tracked, ungated.tracked);
  const double gated_sim3 = Ate(gated, Alignment::kSim3).ape.rmse;
  const double ungated_sim3 = Ate(ungated, Alignment::kSim3).ape.rmse;
  EXPECT_LE(gated_sim3, 0.01) << "metres, at the sim3 scale";
  EXPECT_LE(gated_sim3, 1.2 * ungated_sim3) << "ungated " << ungated_sim3;
}

// The office spans too little depth for the shift to be observable in most views (the fit then
// holds b at 0; FitInverseDepthAffine's own tests cover the shift); what every keyframe must
// recover is the network's scale of that frame, which wanders with the frame's content.
TEST(MonocularTest, TheNetworksPerFrameScaleIsRecovered) {
  SimulatedDepthOptions network = testing_util::FastDepthLikeNetwork(60, 3);
  const size_t frames = 150;
  const OfficeRun run = RunOffice(DepthInput::kNetwork, frames, network);
  ASSERT_GE(run.fits.size(), 5u);
  const SimulatedDepthProvider provider(network, nullptr);
  // z_net = s z and z = m z_map (m: the sim3 scale), so z_map = z_net / (s m): a = s m.
  const double map_to_metric = Ate(run, Alignment::kSim3).gt_from_est.scale;
  int scale_ok = 0, shift_ok = 0, affine = 0;
  double spread = 0;
  for (const auto& [index, fit] : run.fits) {
    const double true_scale = provider.FrameScale(index);
    scale_ok += std::abs(std::log(fit.a / (map_to_metric * true_scale))) < 0.05 ? 1 : 0;
    spread = std::max(spread, std::abs(std::log(true_scale / provider.FrameScale(0))));
    if (!fit.scale_only) {
      ++affine;
      shift_ok += std::abs(fit.b / fit.a) < 0.03 ? 1 : 0;  // no shift in this network
    }
  }
  const int fits = static_cast<int>(run.fits.size());
  EXPECT_GT(spread, 0.1) << "the network's scale must wander for this test to tell";
  EXPECT_GE(scale_ok, 0.8 * fits) << scale_ok << " of " << fits;
  EXPECT_GE(shift_ok, 0.8 * affine) << shift_ok << " of " << affine;
}

// A network with a known per-frame affine distortion in inverse depth (1 / z_out = 1 / (s z) + c,
// both wandering per frame): each keyframe's fit (1 / z_map = a / z_net + b) must recover the
// frame's scale and, where the view spans enough depth for the shift to be observable, its
// shift: -b / a = c in the map's units. The office is shallow, so only about 2 in 5 keyframes
// span enough depth (the other fits hold b at 0); 300 frames give 8 such keyframes.
TEST(MonocularTest, TheNetworksPerFrameAffineDistortionIsRecovered) {
  SimulatedDepthOptions network = testing_util::FastDepthLikeNetwork(60, 3);
  network.shift = 0.05;  // m^-1: 14 % of the inverse depth at 2.8 m
  network.shift_jitter = 0.03;
  const size_t frames = 300;
  const OfficeRun run = RunOffice(DepthInput::kNetwork, frames, network);
  const SimulatedDepthProvider provider(network, nullptr);
  const double map_to_metric = Ate(run, Alignment::kSim3).gt_from_est.scale;
  int scale_ok = 0, shift_ok = 0, affine = 0;
  double true_min = 1e9, true_max = -1e9, fit_min = 1e9, fit_max = -1e9;
  for (const auto& [index, fit] : run.fits) {
    if (fit.scale_only) continue;
    ++affine;
    const double true_scale = provider.FrameScale(index), true_shift = provider.FrameShift(index);
    scale_ok += std::abs(std::log(fit.a / (map_to_metric * true_scale))) < 0.05 ? 1 : 0;
    // -b / a is in the map's inverse depth; the network's shift in metric inverse depth.
    const double shift = -fit.b / fit.a / map_to_metric;
    // Measured: every fit within 0.018 m^-1, most of them 0.007-0.017 low (why: not analysed).
    shift_ok += std::abs(shift - true_shift) < 0.02 ? 1 : 0;
    true_min = std::min(true_min, true_shift), true_max = std::max(true_max, true_shift);
    fit_min = std::min(fit_min, shift), fit_max = std::max(fit_max, shift);
  }
  ASSERT_GE(affine, 5) << "keyframes whose view spans enough depth, of " << run.fits.size();
  EXPECT_GT(true_max - true_min, 0.04) << "the network's shift must wander for this test to tell";
  // The recovered shifts follow the network's: not one constant.
  EXPECT_GT(fit_max - fit_min, 0.7 * (true_max - true_min));
  EXPECT_GE(scale_ok, 0.8 * affine) << scale_ok << " of " << affine;
  EXPECT_GE(shift_ok, 0.8 * affine) << shift_ok << " of " << affine;
}

// mapping.network_scale_prior: a network whose scale is right on every frame (0.88 of the truth,
// no jitter) against geometry's, which drifts from keyframe to keyframe. The prior holds each
// keyframe's scale at the network's, so the keyframes' fitted network scales (a of each fit)
// spread less, and the shape (sim3) is not bent toward the network's depths.
TEST(MonocularTest, TheNetworksScaleHoldsEachKeyFramesScale) {
  SimulatedDepthOptions network = testing_util::FastDepthLikeNetwork(60, 3);
  network.jitter = 0;
  const size_t frames = 300;
  double range[2] = {0, 0}, sim3[2] = {0, 0};
  for (const bool prior : {false, true}) {
    // Measured under ORB-SLAM's keyframe baseline, as the prior was chosen (it is off in the
    // shipped settings). With tracking.keyframe_parallax_baseline the office makes 7 fits, and
    // the prior no longer narrows them: 0.040 -> 0.044, sim3 0.0040 -> 0.0087 m.
    const OfficeRun run = RunOffice(DepthInput::kNetwork, frames, network, 0, prior, false);
    ASSERT_GE(run.fits.size(), 10u);
    double lo = 1e9, hi = -1e9;
    for (const auto& [index, fit] : run.fits) {
      lo = std::min(lo, std::log(fit.a));
      hi = std::max(hi, std::log(fit.a));
    }
    range[prior] = hi - lo;
    sim3[prior] = Ate(run, Alignment::kSim3).ape.rmse;
  }
  // Measured: log-scale range 0.052 without, 0.028 with; sim3 0.0044 / 0.0048 m.
  EXPECT_LT(range[1], 0.7 * range[0]) << "without " << range[0] << " with " << range[1];
  EXPECT_LE(sim3[1], 1.2 * sim3[0]) << "without " << sim3[0] << " with " << sim3[1];
}

// After a long loss in a place relocalisation cannot find, tracking restarts in the same map from
// the network's depth (tracking.reinit_after_lost_frames). The restart's keyframe has only
// single-view points, so the keyframe rule must count them, or the map never grows again: the
// rest of the run would track against that one keyframe. Here a covered lens outlasts the weak
// poses, and the frames after it are the office mirrored, a place the map has never seen (ORB
// descriptors are not mirror-invariant; depth and motion mirror with the image).
// A map built without depth has the scale of its two-view start, not metres: it says so; without
// depth it is tracked as usual; with sensor depth (residuals in metres) its frames are tracked
// without their depths until the first tracked one measures them against the map, which is then
// multiplied by that ratio; with a network, whose depth is a prior measured against the map frame
// by frame, the map takes the network's long-run scale as a new map would.
TEST(MonocularTest, AMapBuiltWithoutDepthTakesTheScaleOfTheDepthItIsLoadedWith) {
  const size_t frames = 150;  // the two-view start waits up to 70 % of them for parallax
  const synth::SceneOptions scene_options = Office(frames);
  const synth::Scene scene = synth::BuildScene(scene_options);
  synth::GeneratorOptions generator;
  generator.scene = scene_options;
  auto frame_at = [&](size_t k, cv::Mat* depth) {
    const synth::RenderedFrame rendered = synth::RenderSceneFrame(scene, k, generator);
    FrameData frame;
    frame.index = k;
    frame.timestamp = scene.TimeOf(k);
    frame.image = rendered.image;
    if (depth != nullptr) *depth = rendered.depth;
    return frame;
  };
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("ademono_scale_free_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path path = dir / "none.map";
  {
    System system(scene.camera, Options(DepthInput::kNone));
    int tracked = 0;
    for (size_t k = 0; k < frames; ++k)
      tracked += system.TrackFrame(frame_at(k, nullptr), {}, {}).tracked;
    ASSERT_GT(tracked, 40);
    system.SaveMap(path);
  }
  const MapFileData data = LoadMapFile(path);
  ASSERT_FALSE(data.keyframes.empty());
  EXPECT_FALSE(MapHasMetricScale(data));
  const std::string text = MapSummaryText(path, SummarizeMap(data, 0));
  EXPECT_NE(text.find("scale: arbitrary (built with --depth none"), std::string::npos) << text;
  EXPECT_NE(text.find("bounding box (map units)"), std::string::npos);

  // Frames [first, end) tracked on the saved map with `input`'s options; `depth_of` turns a
  // frame's rendered depth into the run's (none for DepthInput::kNone). Also tells whether the
  // map had metric scale once they were tracked.
  struct LoadedRun {
    OfficeRun run;
    bool metric_after = false;
  };
  auto track_on_map = [&](DepthInput input, bool localize_only, size_t first, size_t end,
                          const std::function<cv::Mat(const cv::Mat&, size_t)>& depth_of) {
    System system(scene.camera, Options(input));
    system.LoadMap(path, localize_only);
    EXPECT_FALSE(system.LoadedMapHasMetricScale());
    LoadedRun out;
    for (size_t k = first; k < end; ++k) {
      cv::Mat rendered;
      const FrameData frame = frame_at(k, &rendered);
      const cv::Mat depth = depth_of ? depth_of(rendered, k) : cv::Mat();
      out.run.tracked += system.TrackFrame(frame, depth, {}).tracked;
      out.run.truth.push_back({frame.timestamp, scene.world_from_cam(frame.timestamp)});
    }
    system.Shutdown();
    out.run.estimate = system.FrameTrajectory();
    out.metric_after = system.LoadedMapHasMetricScale();
    return out;
  };

  // Without depth: relocalised in the loaded map and tracked on it, in the map's units.
  const LoadedRun geometric = track_on_map(DepthInput::kNone, true, 110, 130, nullptr);
  EXPECT_GT(geometric.run.tracked, 15);
  const double map_to_metric = Ate(geometric.run, Alignment::kSim3).gt_from_est.scale;
  EXPECT_GT(std::abs(std::log(map_to_metric)), std::log(1.3)) << map_to_metric;
  for (const bool localize_only : {false, true}) {
    const LoadedRun sensor = track_on_map(DepthInput::kExact, localize_only, 90, frames,
                                          [](const cv::Mat& depth, size_t) { return depth; });
    EXPECT_TRUE(sensor.metric_after) << "localize_only " << localize_only;
    EXPECT_GT(sensor.run.tracked, 50) << "localize_only " << localize_only;
    // Measured: 0.977 extending the map, 0.962 localising only (the frozen map keeps the scale
    // drift of its geometric start); its own units read 3.83.
    EXPECT_NEAR(Ate(sensor.run, Alignment::kSim3).gt_from_est.scale, 1.0, 0.06)
        << "localize_only " << localize_only;
  }
  // The network reads 0.9x: the frames tracked with it come out at that scale, wherever the
  // loaded map's units were.
  SimulatedDepthOptions network;
  network.scale = 0.9;
  const SimulatedDepthProvider provider(network, nullptr);
  for (const bool localize_only : {false, true}) {
    const LoadedRun with_network =
        track_on_map(DepthInput::kNetwork, localize_only, 90, frames,
                     [&](const cv::Mat& depth, size_t k) { return provider.Degrade(depth, k); });
    EXPECT_GT(with_network.run.tracked, 50) << "localize_only " << localize_only;
    // Measured: 1.045 extending the map, 1.068 localising only (the anchor's tolerance); the
    // map's own units read 3.83.
    EXPECT_NEAR(Ate(with_network.run, Alignment::kSim3).gt_from_est.scale, 1 / 0.9, 0.1)
        << "localize_only " << localize_only;
  }
  std::filesystem::remove_all(dir);
}

TEST(MonocularTest, TheMapGrowsAgainAfterARestart) {
  const SimulatedDepthOptions network = testing_util::FastDepthLikeNetwork(60, 3);
  const size_t frames = 260, gap_begin = 60, gap_end = 110;
  const synth::SceneOptions scene_options = Office(frames);
  const synth::Scene scene = synth::BuildScene(scene_options);
  synth::GeneratorOptions generator;
  generator.scene = scene_options;
  const SimulatedDepthProvider provider(network, nullptr);
  SystemOptions options = Options(DepthInput::kNetwork);
  ASSERT_LT(options.tracking.weak_pose_max_frames + options.tracking.reinit_after_lost_frames,
            static_cast<int>(gap_end - gap_begin));
  System system(scene.camera, options);
  int restarts = 0, keyframes_after = 0, tracked_after = 0;
  bool restarted = false, was_tracked = false;
  for (size_t k = 0; k < frames; ++k) {
    const synth::RenderedFrame rendered = synth::RenderSceneFrame(scene, k, generator);
    FrameData frame;
    frame.index = k;
    frame.timestamp = scene.TimeOf(k);
    cv::Mat depth;
    if (k < gap_begin) {
      frame.image = rendered.image;
      depth = provider.Degrade(rendered.depth, k);
    } else if (k < gap_end) {
      frame.image = cv::Mat::zeros(rendered.image.size(), rendered.image.type());
    } else {
      cv::flip(rendered.image, frame.image, 1);
      cv::flip(provider.Degrade(rendered.depth, k), depth, 1);
    }
    const TrackResult result = system.TrackFrame(frame, depth, {});
    if (k >= gap_end && result.tracked && !was_tracked) {
      EXPECT_FALSE(result.relocalised) << "frame " << k;
      ++restarts;
      restarted = true;
    } else if (restarted) {
      keyframes_after += result.new_keyframe;
    }
    if (restarted) tracked_after += result.tracked;
    was_tracked = result.tracked;
  }
  system.Shutdown();
  ASSERT_EQ(restarts, 1);
  // Measured: 20 keyframes over the 150 frames after the restart, every frame tracked. Before
  // the rule counted single-view points: none (the 150 frames tracked against one keyframe).
  EXPECT_GE(keyframes_after, 8);
  EXPECT_GE(tracked_after, static_cast<int>(frames - gap_end) - 10);
}
// Off the map with the network's depths still measuring each step (tracking.depth_odometry), a
// streak of tracking.reseed_after_odometry_frames such frames re-seeds the map from the frame's
// depths, as a restart after a loss would, without first losing frames: here one office, then
// another seen from the same path, a place the map has never seen. Off, the frames stay weak,
// posed on the last frame's depths or on a few false matches with the old map.
TEST(MonocularTest, ALongStreakOnDepthOdometryReseedsTheMap) {
  const SimulatedDepthOptions network = testing_util::FastDepthLikeNetwork(60, 3);
  const size_t frames = 160, cut = 60;
  // After the cut, another office (other walls, other texture) seen from the same path.
  synth::SceneOptions scene_options[2] = {Office(frames), Office(frames)};
  scene_options[1].seed = 11;
  const synth::Scene scenes[2] = {synth::BuildScene(scene_options[0]),
                                  synth::BuildScene(scene_options[1])};
  const SimulatedDepthProvider provider(network, nullptr);
  for (const int reseed : {0, 10}) {
    SystemOptions options = Options(DepthInput::kNetwork);
    options.tracking.reseed_after_odometry_frames = reseed;
    System system(scenes[0].camera, options);
    int untracked = 0, reseeds = 0, weak_after_cut = 0;
    size_t first_reseed = 0;
    for (size_t k = 0; k < frames; ++k) {
      const int s = k < cut ? 0 : 1;
      synth::GeneratorOptions generator;
      generator.scene = scene_options[s];
      const synth::RenderedFrame rendered = synth::RenderSceneFrame(scenes[s], k, generator);
      FrameData frame;
      frame.index = k;
      frame.timestamp = scenes[s].TimeOf(k);
      frame.image = rendered.image;
      const TrackResult result = system.TrackFrame(frame, provider.Degrade(rendered.depth, k), {});
      untracked += result.tracked ? 0 : 1;
      if (k >= cut && result.quality != PoseQuality::kGood) ++weak_after_cut;
      if (result.new_keyframe && result.quality == PoseQuality::kDepthOdometry) {
        if (reseeds++ == 0) first_reseed = k;
      }
    }
    system.Shutdown();
    RecordProperty("weak_after_cut_reseed_" + std::to_string(reseed), weak_after_cut);
    EXPECT_EQ(untracked, 0) << "reseed " << reseed;
    if (reseed == 0) {
      // Measured: 72 of the 100 frames after the cut posed on the last frame's depths, the rest
      // on a few false matches with the first office's map.
      EXPECT_GE(weak_after_cut, 50);
      EXPECT_EQ(reseeds, 0);
    } else {
      // The frame at the cut has no depth odometry (nothing matches the last frame): the
      // motion model's pose, then the streak. Measured: re-seeded at frame 70, then
      // every frame tracked on the new map.
      ASSERT_GE(reseeds, 1);
      EXPECT_GE(first_reseed, cut + reseed - 1);
      EXPECT_LE(first_reseed, cut + reseed + 5);
      EXPECT_LE(weak_after_cut, reseed + 5);
    }
  }
}

// The metric scale's confidence (per frame, TrackResult::scale_sigma): a network run reports it,
// and it grows with the network's own scale noise; geometry alone and exact depth have no metric
// scale to be unsure of (none, and a sensor's is the sensor's).
TEST(MonocularTest, TheMetricScaleSigmaFollowsTheNetworksNoise) {
  const size_t frames = 150;
  double sigma[2] = {0, 0};
  int k = 0;
  for (const double jitter : {0.04, 0.24}) {
    SimulatedDepthOptions network = testing_util::FastDepthLikeNetwork(20, 3);
    network.jitter = jitter;
    const OfficeRun run = RunOffice(DepthInput::kNetwork, frames, network);
    ASSERT_TRUE(run.last_scale_sigma.has_value()) << "jitter " << jitter;
    EXPECT_GE(run.scale_sigmas, run.tracked - 2) << "jitter " << jitter;
    sigma[k++] = *run.last_scale_sigma;
  }
  // Measured: 0.011 and 0.064.
  EXPECT_GT(sigma[0], 0.0);
  EXPECT_LT(sigma[0], 0.03);
  EXPECT_GT(sigma[1], 3 * sigma[0]) << sigma[0] << " " << sigma[1];
  for (const DepthInput input : {DepthInput::kNone, DepthInput::kExact}) {
    const OfficeRun run = RunOffice(input, 60, {});
    EXPECT_EQ(run.scale_sigmas, 0);
  }
}

}  // namespace
}  // namespace ademono
