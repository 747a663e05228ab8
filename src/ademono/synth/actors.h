#pragma once
// Articulated actors built from boxes: walking persons (torso, head, swinging arms and legs),
// cars and cyclists. Body frames: x forward (heading), y left, z up, origin on the ground.

#include <Eigen/Core>
#include <vector>

#include "ademono/core/geometry.h"
#include "ademono/synth/scene.h"

namespace ademono::synth {

struct PersonLook {
  int shirt = 0, trousers = 0, skin = 0;  // texture indices
  double scale = 1.0;                     // 1.0 = 1.75 m tall
};

struct CarLook {
  int paint = 0, glass = 0, tyre = 0;  // texture indices
};

// A person at `world_from_body` with gait phase `phase` (radians; limbs swing with sin(phase)).
void AppendPerson(const Rigid3d& world_from_body, double phase, const PersonLook& look,
                  int object_id, std::vector<Box>& boxes);
// A car (4.2 x 1.8 x 1.6 m): body, cabin and two axles.
void AppendCar(const Rigid3d& world_from_body, const CarLook& look, int object_id,
               std::vector<Box>& boxes);
// A bicycle (object `bike_id`) with its rider (object `rider_id`) pedalling with `phase`.
void AppendCyclist(const Rigid3d& world_from_body, double phase, const CarLook& bike_look,
                   const PersonLook& rider_look, int bike_id, int rider_id,
                   std::vector<Box>& boxes);

// Walking back and forth between `a` and `b` (on the ground, z ignored) at `speed` m/s,
// starting `offset_m` metres along the out-and-back loop.
struct BackAndForthPath {
  Eigen::Vector3d a{0, 0, 0}, b{1, 0, 0};
  double speed = 1.2;
  double offset_m = 0.0;
  // Body pose at time t and the distance walked so far (for the gait phase).
  Rigid3d WorldFromBody(double t, double* walked_m) const;
};

ActorFunction MakeWalkingPerson(const BackAndForthPath& path, const PersonLook& look,
                                int object_id);
// Straight motion from `world_from_body_at_0` along its x axis at `speed` m/s.
ActorFunction MakeDrivingCar(const Rigid3d& world_from_body_at_0, double speed, const CarLook& look,
                             int object_id);
ActorFunction MakeRidingCyclist(const Rigid3d& world_from_body_at_0, double speed,
                                const CarLook& bike_look, const PersonLook& rider_look, int bike_id,
                                int rider_id);

// A photo sprite (Scene::sprites[sprite], width_m x height_m) standing on the ground at
// `world_from_body`: its quad is the body's x-z plane turned by `yaw` about the body's z axis.
void AppendSprite(const Rigid3d& world_from_body, double yaw, int sprite, double width_m,
                  double height_m, int object_id, std::vector<Box>& boxes);
ActorFunction MakeWalkingSprite(const BackAndForthPath& path, double yaw, int sprite,
                                double width_m, double height_m, int object_id);
ActorFunction MakeDrivingSprite(const Rigid3d& world_from_body_at_0, double speed, double yaw,
                                int sprite, double width_m, double height_m, int object_id);

}  // namespace ademono::synth
