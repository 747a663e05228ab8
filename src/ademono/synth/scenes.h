#pragma once
// The two synthetic worlds.
// - office: a textured room 6 x 5 x 3 m with a desk, shelves and a cabinet; 1-3 persons walk
//   back and forth across the view (COCO person, moving) and a mannequin stands still (person,
//   not moving). Camera like TUM fr3 walking: 30 Hz, 640x480, fx = fy = 525.
// - street: asphalt road with lane markings, sidewalks, building facades on both sides (5 to 40 m
//   to the side) and across the far end (beyond 80 m), parked cars (car, not moving), oncoming
//   and leading cars (car, moving), cyclists (bicycle + person, moving) and a pedestrian.
//   Camera like KITTI: 10 Hz, 1241x376, fx = fy = 718.856, cx = 607.19, cy = 185.22, driving
//   forward at 10 m/s.

#include <cstdint>
#include <optional>
#include <string>

#include "ademono/synth/camera_motion.h"
#include "ademono/synth/scene.h"

namespace ademono::synth {

struct SceneOptions {
  std::string scene = "office";      // "office" | "street"
  std::optional<MotionKind> motion;  // default: xyz (office), forward (street)
  size_t frames = 100;               // the street is built long enough for them (<= 2000)
  uint64_t seed = 0;
  int width = 0, height = 0;  // 0: the scene's default; intrinsics scale with the size
  int persons = 2;            // office: walking persons (1..3)
  // Folder of actor photos (synth/photos.h), empty: procedural actors only. With photos the
  // walking persons, the street's moving cars and its pedestrian are photo cut-outs, and each
  // scene gains movers of no COCO class (a cart and a tumbling cube in the office, a crate and
  // a tumbling cube in the street) that a detector should not box. The street's lead car then
  // follows 8-12 m ahead until it turns off at an intersection, where the camera stops while a
  // photo minibus pulls away across the road (docs/synth.md). Without, the scene is the same as
  // before the option existed (byte-identical outputs).
  std::string actor_photos;
  // Throws std::invalid_argument naming the first bad field.
  void Check() const;
};

Scene BuildScene(const SceneOptions& options);

}  // namespace ademono::synth
