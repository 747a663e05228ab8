#include "ademono/synth/scenes.h"

#include <cmath>
#include <stdexcept>

#include "ademono/synth/actors.h"
#include "ademono/synth/random.h"

namespace ademono::synth {

namespace {

Rigid3d At(double x, double y, double z, double yaw = 0.0) {
  Rigid3d pose = Rigid3d::Identity();
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x, y, z);
  return pose;
}

// Texture streams: every surface draws its seed from (scene seed, running surface number).
class TextureMaker {
 public:
  TextureMaker(Scene& scene, uint64_t seed) : scene_(scene), seed_(seed) {}
  int Make(TextureStyle style, double width_m, double height_m, double texel_m,
           cv::Vec3f tint = {1.f, 1.f, 1.f}) {
    TextureSpec spec;
    spec.style = style;
    spec.width_m = width_m;
    spec.height_m = height_m;
    spec.texel_m = texel_m;
    spec.seed = SubSeed(seed_, ++count_);
    spec.tint = tint;
    return scene_.AddTexture(spec);
  }
  // A texture large enough for every face of a box with these half extents.
  int ForBox(TextureStyle style, const Eigen::Vector3d& half, double texel_m,
             cv::Vec3f tint = {1.f, 1.f, 1.f}) {
    const double side = 2.0 * half.maxCoeff();
    return Make(style, side, side, texel_m, tint);
  }

 private:
  Scene& scene_;
  uint64_t seed_;
  uint64_t count_ = 0;
};

cv::Vec3f RandomTint(Rng& rng, float lo = 0.55f, float hi = 1.15f) {
  return {static_cast<float>(rng.Uniform(lo, hi)), static_cast<float>(rng.Uniform(lo, hi)),
          static_cast<float>(rng.Uniform(lo, hi))};
}

PersonLook MakePersonLook(TextureMaker& textures, Rng& rng, double scale) {
  PersonLook look;
  look.scale = scale;
  look.shirt = textures.ForBox(TextureStyle::kCloth, {0.3, 0.3, 0.3}, 0.004, RandomTint(rng));
  look.trousers =
      textures.ForBox(TextureStyle::kCloth, {0.45, 0.45, 0.45}, 0.004, RandomTint(rng, 0.4f, 0.9f));
  look.skin =
      textures.ForBox(TextureStyle::kSkin, {0.12, 0.12, 0.12}, 0.003, {0.62f, 0.75f, 0.95f});
  return look;
}

Camera ScaledCamera(const Camera& base, int width, int height) {
  if (width == 0 && height == 0) return base;
  const int w = width ? width : base.width, h = height ? height : base.height;
  Camera camera =
      base.Scaled(static_cast<double>(w) / base.width, static_cast<double>(h) / base.height);
  camera.width = w;
  camera.height = h;
  return camera;
}

void BuildOffice(const SceneOptions& options, Scene& scene) {
  Rng rng(SubSeed(options.seed, 0x0FF1CE));
  TextureMaker textures(scene, SubSeed(options.seed, 0x7E87));
  scene.fps = 30.0;
  scene.camera =
      ScaledCamera(Camera::Pinhole(640, 480, 525.0, 319.5, 239.5), options.width, options.height);
  scene.sky_bgr = {0.f, 0.f, 0.f};  // never visible inside the room

  // Room: x in [-3, 3], y in [-2.5, 2.5], z in [0, 3]; one texture per wall.
  Box room;
  room.world_from_box = At(0, 0, 1.5);
  room.half_extents = {3.0, 2.5, 1.5};
  room.inside = true;
  room.face_texture = {
      textures.Make(TextureStyle::kPlaster, 5.0, 3.0, 0.004, {0.9f, 0.97f, 1.0f}),   // -x
      textures.Make(TextureStyle::kPlaster, 5.0, 3.0, 0.004, {1.0f, 0.95f, 0.9f}),   // +x
      textures.Make(TextureStyle::kPlaster, 6.0, 3.0, 0.004, {0.95f, 1.0f, 0.95f}),  // -y
      textures.Make(TextureStyle::kPlaster, 6.0, 3.0, 0.004, {1.0f, 1.0f, 1.0f}),    // +y
      textures.Make(TextureStyle::kFloor, 6.0, 5.0, 0.004, {0.55f, 0.75f, 0.95f}),   // floor
      textures.Make(TextureStyle::kPlaster, 6.0, 5.0, 0.006, {1.0f, 1.0f, 1.0f})};   // ceiling
  scene.static_boxes.push_back(room);

  auto furniture = [&](const Rigid3d& pose, const Eigen::Vector3d& half, TextureStyle style) {
    scene.static_boxes.push_back(
        MakeBox(pose, half, textures.ForBox(style, half, 0.003, RandomTint(rng, 0.6f, 1.1f))));
  };
  // Desk with a monitor, books and a box on it.
  furniture(At(0.0, 1.4, 0.37), {0.8, 0.4, 0.37}, TextureStyle::kWood);
  furniture(At(0.1, 1.55, 0.98), {0.28, 0.03, 0.2}, TextureStyle::kCarPaint);
  furniture(At(-0.5, 1.3, 0.8), {0.12, 0.17, 0.06}, TextureStyle::kCloth);
  furniture(At(0.55, 1.25, 0.84, 0.4), {0.15, 0.1, 0.1}, TextureStyle::kPlaster);
  // Shelves against the front wall with boxes on them, a cabinet on the right, a chair.
  furniture(At(-1.9, 2.25, 0.95), {0.6, 0.2, 0.95}, TextureStyle::kWood);
  furniture(At(-2.1, 2.0, 1.1), {0.15, 0.05, 0.12}, TextureStyle::kCloth);
  furniture(At(-1.6, 2.0, 1.55), {0.2, 0.05, 0.1}, TextureStyle::kPlaster);
  furniture(At(2.2, 2.05, 0.55), {0.5, 0.35, 0.55}, TextureStyle::kWood);
  furniture(At(-0.3, 0.85, 0.25, 0.3), {0.25, 0.25, 0.25}, TextureStyle::kCloth);
  furniture(At(-2.75, 0.0, 0.4), {0.2, 0.7, 0.4}, TextureStyle::kWood);

  // A mannequin that never moves (a person-class object the second dynamic stage must keep).
  {
    const PersonLook look = MakePersonLook(textures, rng, 1.0);
    const int id = scene.AddObject("mannequin", 0, false);
    scene.static_boxes.reserve(scene.static_boxes.size() + 6);
    AppendPerson(At(1.5, 1.7, 0, -M_PI / 2), 0.3, look, id, scene.static_boxes);
  }
  // Walking persons across the view at different distances from the camera (y = -1.6).
  const double lanes[3] = {0.25, -0.45, 0.85};
  for (int i = 0; i < options.persons; ++i) {
    BackAndForthPath path;
    path.a = {-2.5, lanes[i], 0};
    path.b = {2.5, lanes[i] + rng.Uniform(-0.2, 0.2), 0};
    path.speed = rng.Uniform(0.9, 1.3);
    path.offset_m = rng.Uniform(0, 10.0);
    const PersonLook look = MakePersonLook(textures, rng, rng.Uniform(0.93, 1.05));
    const int id = scene.AddObject("person-" + std::to_string(i + 1), 0, true);
    scene.actors.push_back(MakeWalkingPerson(path, look, id));
  }

  MotionSpec motion;
  motion.kind = options.motion.value_or(MotionKind::kXyz);
  const Eigen::Vector3d start(0, -1.6, 1.45);
  motion.base_world_from_cam = LookAt(start, {0, 1.5, 0.95}, {0, 0, 1});
  motion.look_at = {0, 1.4, 0.9};
  motion.forward_speed = 0.15;
  motion.seed = SubSeed(options.seed, 0xCA3);
  scene.world_from_cam = MakeCameraTrajectory(motion);
}

void BuildStreet(const SceneOptions& options, Scene& scene) {
  Rng rng(SubSeed(options.seed, 0x57EE7));
  TextureMaker textures(scene, SubSeed(options.seed, 0x7E88));
  scene.fps = 10.0;
  scene.camera = ScaledCamera(Camera::Pinhole(1241, 376, 718.856, 607.1928, 185.2157),
                              options.width, options.height);
  scene.sky_bgr = {235.f, 205.f, 170.f};

  const double speed = 10.0;
  const double duration = static_cast<double>(options.frames) / scene.fps;
  const double camera_end = speed * duration;
  const double road_begin = -30.0, road_end = camera_end + 130.0;
  const double segment = 25.0;

  // Road (x forward, y left, z up; ground at z = 0) and sidewalks, in segments with their own
  // textures.
  for (double x = road_begin; x < road_end; x += segment) {
    Box road = MakeBox(At(x + segment / 2, 0, -0.05), {segment / 2, 7.0, 0.05},
                       textures.Make(TextureStyle::kRoad, segment, 14.0, 0.02));
    scene.static_boxes.push_back(road);
    for (int side : {-1, 1}) {
      scene.static_boxes.push_back(MakeBox(
          At(x + segment / 2, 9.0 * side, 0.075), {segment / 2, 2.0, 0.075},
          textures.Make(TextureStyle::kSidewalk, segment, 4.0, 0.02, {0.85f, 0.9f, 0.95f})));
    }
  }
  // Open ground (lawns, yards) behind the sidewalks, under and between the buildings.
  for (double x = road_begin; x < road_end + 20; x += 2 * segment) {
    for (int side : {-1, 1}) {
      scene.static_boxes.push_back(MakeBox(
          At(x + segment, 36.0 * side, -0.05), {segment, 25.0, 0.05},
          textures.Make(TextureStyle::kFloor, 2 * segment, 50.0, 0.08, {0.45f, 0.8f, 0.55f})));
    }
  }
  // Buildings along both sides; facades 11 to 40 m to the side.
  for (int side : {-1, 1}) {
    double x = road_begin + rng.Uniform(0, 10);
    while (x < road_end) {
      const double length = rng.Uniform(8, 25), height = rng.Uniform(8, 30), depth = 10.0;
      const double setback = rng.Uniform() < 0.7 ? 11.0 + rng.Uniform(0, 4) : rng.Uniform(15, 40);
      Box building = MakeBox(At(x + length / 2, side * (setback + depth / 2), height / 2),
                             {length / 2, depth / 2, height / 2}, 0);
      const cv::Vec3f tint = RandomTint(rng, 0.6f, 1.1f);
      const int front = textures.Make(TextureStyle::kFacade, length, height, 0.05, tint);
      const int ends = textures.Make(TextureStyle::kFacade, depth, height, 0.05, tint);
      building.face_texture = {ends, ends, front, front, front, front};
      scene.static_boxes.push_back(building);
      x += length + (rng.Uniform() < 0.5 ? 0.0 : rng.Uniform(2, 8));
    }
  }
  // Buildings across the far end, always beyond 80 m from the camera.
  for (double y = -60; y < 60; y += 20) {
    const double height = rng.Uniform(12, 35);
    Box building = MakeBox(At(road_end + 5 + rng.Uniform(0, 10), y + 10, height / 2),
                           {5.0, 10.0, height / 2}, 0);
    building.face_texture.fill(
        textures.Make(TextureStyle::kFacade, 20.0, height, 0.1, RandomTint(rng, 0.6f, 1.1f)));
    scene.static_boxes.push_back(building);
  }

  auto car_look = [&]() {
    CarLook look;
    look.paint = textures.ForBox(TextureStyle::kCarPaint, {2.1, 2.1, 2.1}, 0.01,
                                 RandomTint(rng, 0.3f, 1.2f));
    look.glass = textures.ForBox(TextureStyle::kDark, {1.1, 1.1, 1.1}, 0.01);
    look.tyre = textures.ForBox(TextureStyle::kDark, {0.93, 0.93, 0.93}, 0.01, {0.8f, 0.8f, 0.8f});
    return look;
  };
  // Parked cars in the parking lanes (|y| = 5.6), heading either way.
  int parked = 0;
  for (int side : {-1, 1}) {
    for (double x = road_begin + rng.Uniform(0, 10); x < road_end - 20; x += rng.Uniform(6, 20)) {
      if (rng.Uniform() < 0.25) continue;
      const int id = scene.AddObject("parked-car-" + std::to_string(++parked), 2, false);
      AppendCar(At(x, 5.6 * side, 0, rng.Uniform() < 0.5 ? 0.0 : M_PI), car_look(), id,
                scene.static_boxes);
    }
  }
  // Moving cars: one leading in the camera's lane, oncoming ones passing at spread-out times.
  {
    const int id = scene.AddObject("car-lead", 2, true);
    scene.actors.push_back(MakeDrivingCar(At(rng.Uniform(15, 22), -1.75, 0),
                                          speed * rng.Uniform(0.9, 1.05), car_look(), id));
  }
  const int oncoming = 2 + static_cast<int>(rng.Next() % 2);
  for (int i = 0; i < oncoming; ++i) {
    const double car_speed = rng.Uniform(8, 12);
    const double pass_time = (i + rng.Uniform(0.3, 0.9)) * std::max(duration, 4.0) / oncoming;
    // Passing the camera (x = speed * pass_time) at pass_time.
    const double x0 = speed * pass_time + car_speed * pass_time;
    const int id = scene.AddObject("car-oncoming-" + std::to_string(i + 1), 2, true);
    scene.actors.push_back(MakeDrivingCar(At(x0, 1.75, 0, M_PI), car_speed, car_look(), id));
  }
  // Cyclists in the bike lane, overtaken by the camera.
  for (int i = 0; i < 2; ++i) {
    CarLook bike = car_look();
    const PersonLook rider = MakePersonLook(textures, rng, rng.Uniform(0.95, 1.05));
    const int bike_id = scene.AddObject("bicycle-" + std::to_string(i + 1), 1, true);
    const int rider_id = scene.AddObject("cyclist-" + std::to_string(i + 1), 0, true);
    scene.actors.push_back(MakeRidingCyclist(At(12.0 + 30.0 * i + rng.Uniform(0, 10), -4.0, 0),
                                             rng.Uniform(3.5, 5.5), bike, rider, bike_id,
                                             rider_id));
  }
  // A pedestrian walking along the right sidewalk.
  {
    BackAndForthPath path;
    path.a = {20, -9.5, 0};
    path.b = {60, -9.0, 0};
    path.speed = 1.3;
    const int id = scene.AddObject("pedestrian", 0, true);
    scene.actors.push_back(MakeWalkingPerson(path, MakePersonLook(textures, rng, 1.0), id));
  }

  MotionSpec motion;
  motion.kind = options.motion.value_or(MotionKind::kForward);
  const Eigen::Vector3d start(0, -1.75, 1.65);
  motion.base_world_from_cam = LookAt(start, start + Eigen::Vector3d(1, 0, 0), {0, 0, 1});
  motion.look_at = start + Eigen::Vector3d(20, 0, -1.0);
  motion.forward_speed = speed;
  motion.jitter_translation_m = 0.01;  // a car on a road: small bumps
  motion.jitter_rotation_rad = 0.002;
  motion.seed = SubSeed(options.seed, 0xCA4);
  scene.world_from_cam = MakeCameraTrajectory(motion);
}

}  // namespace

void SceneOptions::Check() const {
  if (scene != "office" && scene != "street")
    throw std::invalid_argument("unknown scene '" + scene + "' (expected office or street)");
  if (frames < 1 || frames > 100000) throw std::invalid_argument("frames must be in [1, 100000]");
  // The street is built (and textured) for the whole drive up front: ~16 MB of textures per
  // 100 m, so it is capped at 2000 frames (2 km).
  if (scene == "street" && frames > 2000)
    throw std::invalid_argument("street: frames must be in [1, 2000] (the road is 1 m per frame)");
  if (width < 0 || height < 0 || (width > 0 && width < 16) || (height > 0 && height < 16) ||
      width > 8192 || height > 8192)
    throw std::invalid_argument("width and height must be in [16, 8192]");
  if (persons < 1 || persons > 3) throw std::invalid_argument("persons must be 1, 2 or 3");
}

Scene BuildScene(const SceneOptions& options) {
  options.Check();
  Scene scene;
  scene.name = options.scene;
  if (options.scene == "office") {
    BuildOffice(options, scene);
  } else {
    BuildStreet(options, scene);
  }
  return scene;
}

}  // namespace ademono::synth
