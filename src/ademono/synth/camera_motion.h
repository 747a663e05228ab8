#pragma once
// Camera trajectories of the synthetic sequences, like the TUM fr3 "walking" recordings
// (xyz, halfsphere, rpy, static), a car driving forward (street) and a closed loop that comes
// back to its start and revisits the first views (loop closure tests). All are smooth functions of
// time with a seeded handheld jitter on top.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>

#include "ademono/core/geometry.h"

namespace ademono::synth {

enum class MotionKind { kXyz, kHalfsphere, kRpy, kStatic, kForward, kLoop };

// "xyz" | "halfsphere" | "rpy" | "static" | "forward" | "loop"; std::invalid_argument otherwise.
MotionKind ParseMotionKind(const std::string& name);
std::string MotionKindName(MotionKind kind);

struct MotionSpec {
  MotionKind kind = MotionKind::kXyz;
  Rigid3d base_world_from_cam = Rigid3d::Identity();  // pose at t = 0 (before jitter)
  Eigen::Vector3d look_at{0, 0, 0};                   // halfsphere: the point watched
  Eigen::Vector3d world_up{0, 0, 1};
  double forward_speed = 0.0;           // m/s along the camera's optical axis (forward)
  // loop: an ellipse in the horizontal plane through loop_centre (radii along world x and y),
  // counter-clockwise seen from above, the camera looking outwards (pitched down by
  // loop_pitch_rad), one lap per loop_period_s starting at angle loop_start_rad (0 = +x).
  Eigen::Vector3d loop_centre{0, 0, 0};
  Eigen::Vector2d loop_radii{1, 1};
  double loop_period_s = 10.0;
  double loop_start_rad = 0.0;
  double loop_pitch_rad = 0.0;
  bool loop_look_ahead = false;  // look along the path (a car) instead of outwards
  double jitter_translation_m = 0.003;  // per-axis amplitude of the handheld jitter
  double jitter_rotation_rad = 0.004;
  uint64_t seed = 0;
};

// world_from_cam(t), deterministic for a spec.
std::function<Rigid3d(double)> MakeCameraTrajectory(const MotionSpec& spec);

// The camera pose at `position` looking at `target` with image "up" along `world_up`.
Rigid3d LookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& target,
               const Eigen::Vector3d& world_up);

}  // namespace ademono::synth
