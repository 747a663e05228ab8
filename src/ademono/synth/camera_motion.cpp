#include "ademono/synth/camera_motion.h"

#include <array>
#include <cmath>
#include <stdexcept>

#include "ademono/synth/random.h"

namespace ademono::synth {

namespace {

constexpr double kTwoPi = 2.0 * M_PI;

// Smooth pseudo-random signal: three sinusoids of random frequency (0.4..2.5 Hz) and phase,
// normalised so the amplitude is about `amplitude`.
struct Wobble {
  std::array<double, 3> frequency{}, phase{}, weight{};
  Wobble(Rng& rng) {
    for (int i = 0; i < 3; ++i) {
      frequency[i] = rng.Uniform(0.4, 2.5);
      phase[i] = rng.Uniform(0, kTwoPi);
      weight[i] = rng.Uniform(0.5, 1.0);
    }
    const double sum = weight[0] + weight[1] + weight[2];
    for (double& w : weight) w /= sum;
  }
  double operator()(double t) const {
    double value = 0;
    for (int i = 0; i < 3; ++i) value += weight[i] * std::sin(kTwoPi * frequency[i] * t + phase[i]);
    return value;
  }
};

}  // namespace

MotionKind ParseMotionKind(const std::string& name) {
  if (name == "xyz") return MotionKind::kXyz;
  if (name == "halfsphere") return MotionKind::kHalfsphere;
  if (name == "rpy") return MotionKind::kRpy;
  if (name == "static") return MotionKind::kStatic;
  if (name == "forward") return MotionKind::kForward;
  if (name == "loop") return MotionKind::kLoop;
  throw std::invalid_argument("unknown motion '" + name +
                              "' (expected xyz, halfsphere, rpy, static, forward or loop)");
}

std::string MotionKindName(MotionKind kind) {
  switch (kind) {
    case MotionKind::kXyz:
      return "xyz";
    case MotionKind::kHalfsphere:
      return "halfsphere";
    case MotionKind::kRpy:
      return "rpy";
    case MotionKind::kStatic:
      return "static";
    case MotionKind::kForward:
      return "forward";
    case MotionKind::kLoop:
      return "loop";
  }
  return "?";
}

Rigid3d LookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& target,
               const Eigen::Vector3d& world_up) {
  const Eigen::Vector3d z = (target - position).normalized();
  const Eigen::Vector3d x = z.cross(world_up).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Rigid3d world_from_cam = Rigid3d::Identity();
  world_from_cam.linear().col(0) = x;
  world_from_cam.linear().col(1) = y;
  world_from_cam.linear().col(2) = z;
  world_from_cam.translation() = position;
  return world_from_cam;
}

std::function<Rigid3d(double)> MakeCameraTrajectory(const MotionSpec& spec) {
  Rng rng(SubSeed(spec.seed, 0xCA3E7A));
  std::array<Wobble, 6> jitter{Wobble(rng), Wobble(rng), Wobble(rng),
                               Wobble(rng), Wobble(rng), Wobble(rng)};
  return [spec, jitter](double t) {
    Rigid3d world_from_cam = spec.base_world_from_cam;
    const Eigen::Matrix3d base_rotation = spec.base_world_from_cam.linear();
    switch (spec.kind) {
      case MotionKind::kXyz: {
        // Back and forth along the camera axes, +-0.3 m sideways, +-0.2 m up/down and in depth.
        const Eigen::Vector3d offset(0.30 * std::sin(kTwoPi * t / 6.0),
                                     0.20 * std::sin(kTwoPi * t / 8.0 + 1.0),
                                     0.20 * std::sin(kTwoPi * t / 10.0 + 2.0));
        world_from_cam.translation() += base_rotation * offset;
        break;
      }
      case MotionKind::kHalfsphere: {
        // On a sphere of radius 0.6 m in front of the start position, watching `look_at`.
        const double radius = 0.6;
        const Eigen::Vector3d forward = base_rotation.col(2), right = base_rotation.col(0);
        const Eigen::Vector3d up = -base_rotation.col(1);
        const Eigen::Vector3d centre = spec.base_world_from_cam.translation() + radius * forward;
        const double azimuth = 1.0 * std::sin(kTwoPi * t / 12.0);
        const double elevation = 0.5 * std::sin(kTwoPi * t / 8.0);
        const Eigen::Vector3d position =
            centre -
            radius * (std::cos(elevation) * std::cos(azimuth) * forward +
                      std::cos(elevation) * std::sin(azimuth) * right + std::sin(elevation) * up);
        world_from_cam = LookAt(position, spec.look_at, spec.world_up);
        break;
      }
      case MotionKind::kRpy: {
        const Eigen::Vector3d omega(0.17 * std::sin(kTwoPi * t / 5.0),   // pitch (camera x)
                                    0.35 * std::sin(kTwoPi * t / 9.0),   // yaw (camera y)
                                    0.26 * std::sin(kTwoPi * t / 7.0));  // roll (optical axis)
        world_from_cam.linear() = base_rotation * ExpSO3(omega);
        break;
      }
      case MotionKind::kStatic:
        break;
      case MotionKind::kForward:
        world_from_cam.translation() += base_rotation.col(2) * (spec.forward_speed * t);
        break;
      case MotionKind::kLoop: {
        const double angle = spec.loop_start_rad + kTwoPi * t / spec.loop_period_s;
        const Eigen::Vector3d radial(std::cos(angle), std::sin(angle), 0.0);
        const Eigen::Vector3d position =
            spec.loop_centre + Eigen::Vector3d(spec.loop_radii.x() * radial.x(),
                                               spec.loop_radii.y() * radial.y(), 0.0);
        const Eigen::Vector3d tangent(-spec.loop_radii.x() * std::sin(angle),
                                      spec.loop_radii.y() * std::cos(angle), 0.0);
        const Eigen::Vector3d ahead = spec.loop_look_ahead ? tangent.normalized() : radial;
        const Eigen::Vector3d view = ahead - std::tan(spec.loop_pitch_rad) * spec.world_up;
        world_from_cam = LookAt(position, position + view, spec.world_up);
        break;
      }
    }
    const Eigen::Vector3d shake_translation(jitter[0](t), jitter[1](t), jitter[2](t));
    const Eigen::Vector3d shake_rotation(jitter[3](t), jitter[4](t), jitter[5](t));
    Rigid3d shaken = world_from_cam;
    shaken.translation() += world_from_cam.linear() * shake_translation * spec.jitter_translation_m;
    shaken.linear() = world_from_cam.linear() * ExpSO3(shake_rotation * spec.jitter_rotation_rad);
    return shaken;
  };
}

}  // namespace ademono::synth
