#pragma once
// The simulated network of the SLAM tests and the soak benchmark: exact synthetic depth degraded
// like FastDepth's on 7-Scenes (reads 0.88x the sensor, per-frame log-scale spread 0.16), the
// settings a network-depth run uses on the small office renders, and the back-and-forth frame
// order that revisits the same places.

#include <cstddef>
#include <cstdint>

#include "ademono/depth/simulated_depth.h"
#include "ademono/slam/options.h"

namespace ademono::testing_util {

// FastDepth on seq-a: about 0.88x the sensor, its per-frame scale wandering with spread 0.16 over
// `jitter_frames`.
inline SimulatedDepthOptions FastDepthLikeNetwork(size_t jitter_frames, uint64_t seed) {
  SimulatedDepthOptions options;
  options.scale = 0.88;
  options.jitter = 0.16;
  options.jitter_frames = jitter_frames;
  options.seed = seed;
  return options;
}

// Network-depth settings for the 320x240 / 640x480 office renders (as configs/network_indoor.yaml
// with the tests' smaller feature budget; dynamic removal off: these tests are about depth).
inline SystemOptions SimulatedNetworkOptions() {
  SystemOptions options;
  options.orb.num_features = 1000;
  options.depth.min_depth = 0.1;
  options.depth.max_depth = 10.0;
  options.depth.virtual_baseline = 0.03;
  options.depth.close_depth_factor = 107;
  options.depth.error_relative = 0.5;
  options.depth.edge_radius = 3;
  options.depth.edge_relative_slope = 0.2;
  options.tracking.min_init_points = 50;
  options.tracking.close_tracked_min = 250;
  options.mapping.ba_max_keyframes = 20;
  options.mapping.triangulation = true;
  options.filter.enable_dynamic_removal = false;
  return options;
}

// Frame k of a path played forwards then backwards over `period` rendered frames: 0, 1, ...,
// period - 1, period - 2, ..., 0, 1, ... A continuous path (no jump) that keeps revisiting the
// same places, so a map can saturate.
inline size_t BackAndForthFrame(size_t k, size_t period) {
  const size_t cycle = 2 * period - 2;
  const size_t m = k % cycle;
  return m < period ? m : cycle - m;
}

}  // namespace ademono::testing_util
