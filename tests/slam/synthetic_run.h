#pragma once
// Tracks every frame of a rendered synthetic scene through a System, with the scene's depth
// degraded by a simulated network: the loop the network-depth, ground-scale and loop-closing
// tests share.

#include "ademono/depth/simulated_depth.h"
#include "ademono/io/trajectory.h"
#include "ademono/slam/system.h"
#include "ademono/synth/generator.h"
#include "ademono/synth/scenes.h"

namespace ademono::testing_util {

struct SyntheticRun {
  int tracked = 0;
  Trajectory truth;  // world_from_cam of every frame
};

// Frames 0 .. options.frames - 1 of `scene` (built from `options`), in order; the caller shuts
// the system down.
inline SyntheticRun TrackSyntheticScene(const synth::Scene& scene,
                                        const synth::SceneOptions& options,
                                        const SimulatedDepthProvider& network, System& system) {
  synth::GeneratorOptions generator;
  generator.scene = options;
  SyntheticRun run;
  for (size_t k = 0; k < options.frames; ++k) {
    const synth::RenderedFrame rendered = synth::RenderSceneFrame(scene, k, generator);
    FrameData frame;
    frame.index = k;
    frame.timestamp = scene.TimeOf(k);
    frame.image = rendered.image;
    run.tracked += system.TrackFrame(frame, network.Degrade(rendered.depth, k), {}).tracked;
    run.truth.push_back({frame.timestamp, scene.world_from_cam(frame.timestamp)});
  }
  return run;
}

}  // namespace ademono::testing_util
