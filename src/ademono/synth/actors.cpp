#include "ademono/synth/actors.h"

#include <cmath>

namespace ademono::synth {

namespace {

Rigid3d Translation(double x, double y, double z) {
  Rigid3d pose = Rigid3d::Identity();
  pose.translation() = Eigen::Vector3d(x, y, z);
  return pose;
}

Rigid3d RotationY(double angle) {
  Rigid3d pose = Rigid3d::Identity();
  pose.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return pose;
}

// A limb of half length `half_length` hanging from `joint` (body frame), swung by `angle`
// about the body's y axis.
Box Limb(const Rigid3d& world_from_body, const Eigen::Vector3d& joint, double angle,
         const Eigen::Vector3d& half, int texture, int object_id) {
  const Rigid3d body_from_limb = Translation(joint.x(), joint.y(), joint.z()) * RotationY(angle) *
                                 Translation(0, 0, -half.z());
  return MakeBox(world_from_body * body_from_limb, half, texture, object_id);
}

constexpr double kStride = 1.4;  // metres per gait cycle

}  // namespace

void AppendPerson(const Rigid3d& world_from_body, double phase, const PersonLook& look,
                  int object_id, std::vector<Box>& boxes) {
  const double s = look.scale;
  const double swing = std::sin(phase);
  for (int side : {-1, 1}) {
    boxes.push_back(Limb(world_from_body, s * Eigen::Vector3d(0, 0.1 * side, 0.9),
                         0.45 * swing * side, s * Eigen::Vector3d(0.07, 0.07, 0.45), look.trousers,
                         object_id));
    boxes.push_back(Limb(world_from_body, s * Eigen::Vector3d(0, 0.29 * side, 1.46),
                         -0.4 * swing * side, s * Eigen::Vector3d(0.05, 0.05, 0.32), look.shirt,
                         object_id));
  }
  boxes.push_back(MakeBox(world_from_body * Translation(0, 0, 1.2 * s),
                          s * Eigen::Vector3d(0.12, 0.22, 0.3), look.shirt, object_id));
  boxes.push_back(MakeBox(world_from_body * Translation(0.01 * s, 0, 1.63 * s),
                          s * Eigen::Vector3d(0.1, 0.09, 0.12), look.skin, object_id));
}

void AppendCar(const Rigid3d& world_from_body, const CarLook& look, int object_id,
               std::vector<Box>& boxes) {
  boxes.push_back(
      MakeBox(world_from_body * Translation(0, 0, 0.65), {2.1, 0.9, 0.38}, look.paint, object_id));
  Box cabin = MakeBox(world_from_body * Translation(-0.25, 0, 1.3), {1.1, 0.82, 0.28}, look.glass,
                      object_id);
  cabin.face_texture[5] = look.paint;  // roof
  boxes.push_back(cabin);
  for (double x : {-1.35, 1.35}) {
    boxes.push_back(MakeBox(world_from_body * Translation(x, 0, 0.33), {0.33, 0.93, 0.33},
                            look.tyre, object_id));
  }
}

void AppendCyclist(const Rigid3d& world_from_body, double phase, const CarLook& bike_look,
                   const PersonLook& rider_look, int bike_id, int rider_id,
                   std::vector<Box>& boxes) {
  // Bicycle: two wheels, frame, handlebar.
  for (double x : {-0.55, 0.55}) {
    boxes.push_back(MakeBox(world_from_body * Translation(x, 0, 0.34), {0.34, 0.025, 0.34},
                            bike_look.tyre, bike_id));
  }
  boxes.push_back(MakeBox(world_from_body * Translation(0, 0, 0.62), {0.5, 0.03, 0.1},
                          bike_look.paint, bike_id));
  boxes.push_back(MakeBox(world_from_body * Translation(0.45, 0, 1.0), {0.04, 0.3, 0.04},
                          bike_look.paint, bike_id));
  // Rider: leaning torso, head, pedalling legs, arms to the handlebar.
  const double s = rider_look.scale;
  boxes.push_back(MakeBox(world_from_body * Translation(-0.05, 0, 1.25 * s) * RotationY(0.5),
                          s * Eigen::Vector3d(0.12, 0.2, 0.3), rider_look.shirt, rider_id));
  boxes.push_back(MakeBox(world_from_body * Translation(0.2, 0, 1.62 * s),
                          s * Eigen::Vector3d(0.1, 0.09, 0.12), rider_look.skin, rider_id));
  for (int side : {-1, 1}) {
    const double pedal = phase + (side > 0 ? 0.0 : M_PI);
    boxes.push_back(Limb(world_from_body, Eigen::Vector3d(-0.15, 0.11 * side, 0.98 * s),
                         -0.5 + 0.45 * std::sin(pedal), s * Eigen::Vector3d(0.065, 0.065, 0.4),
                         rider_look.trousers, rider_id));
    boxes.push_back(Limb(world_from_body, Eigen::Vector3d(0.05, 0.24 * side, 1.45 * s), -0.9,
                         s * Eigen::Vector3d(0.045, 0.045, 0.3), rider_look.shirt, rider_id));
  }
}

Rigid3d BackAndForthPath::WorldFromBody(double t, double* walked_m) const {
  Eigen::Vector3d ground_a(a.x(), a.y(), 0), ground_b(b.x(), b.y(), 0);
  const double length = (ground_b - ground_a).norm();
  const Eigen::Vector3d direction = (ground_b - ground_a) / length;
  const double walked = offset_m + speed * t;
  const double s = std::fmod(walked, 2.0 * length);
  const bool outward = s < length;
  const Eigen::Vector3d position = outward ? Eigen::Vector3d(ground_a + s * direction)
                                           : Eigen::Vector3d(ground_b - (s - length) * direction);
  const Eigen::Vector3d heading = outward ? direction : Eigen::Vector3d(-direction);
  Rigid3d pose = Rigid3d::Identity();
  pose.linear().col(0) = heading;
  pose.linear().col(1) = Eigen::Vector3d::UnitZ().cross(heading);
  pose.linear().col(2) = Eigen::Vector3d::UnitZ();
  pose.translation() = position;
  if (walked_m) *walked_m = walked;
  return pose;
}

ActorFunction MakeWalkingPerson(const BackAndForthPath& path, const PersonLook& look,
                                int object_id) {
  return [path, look, object_id](double t, std::vector<Box>& boxes) {
    double walked = 0.0;
    const Rigid3d world_from_body = path.WorldFromBody(t, &walked);
    AppendPerson(world_from_body, 2.0 * M_PI * walked / kStride, look, object_id, boxes);
  };
}

ActorFunction MakeDrivingCar(const Rigid3d& world_from_body_at_0, double speed, const CarLook& look,
                             int object_id) {
  return [world_from_body_at_0, speed, look, object_id](double t, std::vector<Box>& boxes) {
    AppendCar(world_from_body_at_0 * Translation(speed * t, 0, 0), look, object_id, boxes);
  };
}

ActorFunction MakeRidingCyclist(const Rigid3d& world_from_body_at_0, double speed,
                                const CarLook& bike_look, const PersonLook& rider_look, int bike_id,
                                int rider_id) {
  return [=](double t, std::vector<Box>& boxes) {
    // One pedal turn per ~4.5 m.
    AppendCyclist(world_from_body_at_0 * Translation(speed * t, 0, 0), 2.0 * M_PI * speed * t / 4.5,
                  bike_look, rider_look, bike_id, rider_id, boxes);
  };
}

void AppendSprite(const Rigid3d& world_from_body, double yaw, int sprite, double width_m,
                  double height_m, int object_id, std::vector<Box>& boxes) {
  Rigid3d body_from_quad = Translation(0, 0, height_m / 2);
  body_from_quad.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  // A thin box only bounds the quad for culling; the renderer intersects the plane y = 0.
  Box box = MakeBox(world_from_body * body_from_quad, {width_m / 2, 0.005, height_m / 2}, 0,
                    object_id);
  box.sprite = sprite;
  boxes.push_back(box);
}

ActorFunction MakeWalkingSprite(const BackAndForthPath& path, double yaw, int sprite,
                                double width_m, double height_m, int object_id) {
  return [=](double t, std::vector<Box>& boxes) {
    AppendSprite(path.WorldFromBody(t, nullptr), yaw, sprite, width_m, height_m, object_id, boxes);
  };
}

ActorFunction MakeDrivingSprite(const Rigid3d& world_from_body_at_0, double speed, double yaw,
                                int sprite, double width_m, double height_m, int object_id) {
  return [=](double t, std::vector<Box>& boxes) {
    AppendSprite(world_from_body_at_0 * Translation(speed * t, 0, 0), yaw, sprite, width_m,
                 height_m, object_id, boxes);
  };
}

}  // namespace ademono::synth
