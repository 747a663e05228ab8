#include "ademono/synth/scenes.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "ademono/synth/actors.h"
#include "ademono/synth/photos.h"
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

// One lap of the loop motion takes 85 % of the sequence.
double LoopPeriod(const SceneOptions& options, double fps) {
  return 0.85 * static_cast<double>(options.frames) / fps;
}

// Adds a sprite cut from `cutout`, `height_m` tall; returns its index.
int AddSprite(Scene& scene, const PhotoCutout& cutout, double height_m) {
  scene.sprites.push_back(Sprite::FromCutout(cutout.bgr, cutout.alpha, height_m));
  return static_cast<int>(scene.sprites.size()) - 1;
}

// Walker `id` on `path`: the photo `cutout` as a sprite `height_m` tall, its quad turned by `yaw`
// from the walking direction; without a cutout, the textured person `look`.
void AddWalker(Scene& scene, const BackAndForthPath& path, const PersonLook& look, int id,
               const PhotoCutout* cutout, double height_m, double yaw) {
  if (cutout == nullptr) {
    scene.actors.push_back(MakeWalkingPerson(path, look, id));
    return;
  }
  const int sprite = AddSprite(scene, *cutout, height_m);
  scene.objects[id - 1].appearance = cutout->source;
  scene.actors.push_back(MakeWalkingSprite(path, yaw, sprite, scene.sprites[sprite].width_m(),
                                           scene.sprites[sprite].height_m(), id));
}

// A box of no COCO class carried along `path` (ground z = 0 at `height_m` above it) and
// turning about `axis` at `spin` rad/s: a mover no detector has a name for. Adds the object
// `name` (moving, no class) and its actor.
void AddTumblingBox(Scene& scene, const std::string& name, const BackAndForthPath& path,
                    double height_m, const Eigen::Vector3d& half, const Eigen::Vector3d& axis,
                    double spin, int texture) {
  const int object_id = scene.AddObject(name, -1, true);
  scene.actors.push_back([=](double t, std::vector<Box>& boxes) {
    Rigid3d pose = path.WorldFromBody(t, nullptr);
    pose.translation().z() += height_m;
    if (spin != 0.0)
      pose.linear() =
          pose.linear() * Eigen::AngleAxisd(spin * t, axis.normalized()).toRotationMatrix();
    boxes.push_back(MakeBox(pose, half, texture, object_id));
  });
}

void BuildOffice(const SceneOptions& options, const ActorPhotos* photos, Scene& scene) {
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
  // Walking persons across the view at different distances from the camera (y = -1.6). The loop
  // motion circles the middle of the room, so there they walk along the near wall instead.
  const bool loop = options.motion == MotionKind::kLoop;
  const double lanes[3] = {0.25, -0.45, 0.85};
  const double loop_lanes[3] = {-1.95, -2.1, -1.8};
  for (int i = 0; i < options.persons; ++i) {
    const double lane = loop ? loop_lanes[i] : lanes[i];
    BackAndForthPath path;
    path.a = {-2.5, lane, 0};
    path.b = {2.5, lane + rng.Uniform(-0.2, 0.2) * (loop ? 0.5 : 1.0), 0};
    path.speed = rng.Uniform(0.9, 1.3);
    path.offset_m = rng.Uniform(0, 10.0);
    const PersonLook look = MakePersonLook(textures, rng, rng.Uniform(0.93, 1.05));
    const int id = scene.AddObject("person-" + std::to_string(i + 1), 0, true);
    // With photos: the photo person on the walker's path, its quad along the walking direction
    // (seen from the front by the camera looking across the paths).
    AddWalker(scene, path, look, id,
              photos ? &photos->persons[i % photos->persons.size()] : nullptr,
              1.75 * look.scale, 0.0);
  }
  if (photos) {
    // Movers of no COCO class, drawn from their own streams (the rest of the scene unchanged).
    Rng decoy(SubSeed(options.seed, 0xDEC0));
    TextureMaker decoy_textures(scene, SubSeed(options.seed, 0xDEC1));
    BackAndForthPath cart_path;
    cart_path.a = {-2.3, -0.1, 0};
    cart_path.b = {2.3, -0.1 + decoy.Uniform(-0.2, 0.2), 0};
    cart_path.speed = decoy.Uniform(0.5, 0.8);
    cart_path.offset_m = decoy.Uniform(0, 9.0);
    const Eigen::Vector3d cart_half(0.3, 0.22, 0.35);
    AddTumblingBox(
        scene, "cart", cart_path, cart_half.z(), cart_half, Eigen::Vector3d::UnitZ(), 0.0,
        decoy_textures.ForBox(TextureStyle::kCarPaint, cart_half, 0.003, RandomTint(decoy)));
    BackAndForthPath cube_path;
    cube_path.a = {-2.0, 0.5, 0};
    cube_path.b = {2.0, 0.5 + decoy.Uniform(-0.3, 0.3), 0};
    cube_path.speed = decoy.Uniform(0.4, 0.7);
    cube_path.offset_m = decoy.Uniform(0, 8.0);
    const Eigen::Vector3d cube_half(0.17, 0.17, 0.17);
    AddTumblingBox(
        scene, "tumbling-cube", cube_path, 1.3, cube_half, Eigen::Vector3d(1.0, 0.6, 0.3), 1.5,
        decoy_textures.ForBox(TextureStyle::kCloth, cube_half, 0.003, RandomTint(decoy)));
  }

  MotionSpec motion;
  motion.kind = options.motion.value_or(MotionKind::kXyz);
  const Eigen::Vector3d start(0, -1.6, 1.45);
  motion.base_world_from_cam = LookAt(start, {0, 1.5, 0.95}, {0, 0, 1});
  motion.look_at = {0, 1.4, 0.9};
  motion.forward_speed = 0.15;
  // loop: an ellipse 3 x 2 m around the room's middle, looking at the walls 1.3-1.7 m away;
  // one lap takes 85 % of the sequence, so its last 15 % revisit the first views (the desk).
  motion.loop_centre = {0, -0.2, 1.45};
  motion.loop_radii = {1.5, 1.0};
  motion.loop_period_s = LoopPeriod(options, scene.fps);
  motion.loop_start_rad = M_PI / 2;
  motion.loop_pitch_rad = 0.15;
  motion.seed = SubSeed(options.seed, 0xCA3);
  scene.world_from_cam = MakeCameraTrajectory(motion);
}

// The street's intersection (photos only), as on a KITTI drive: a city bus crosses the junction
// from right to left at a steady 2.5-3.5 m/s (on the cross street, broadside to the camera), so
// it is moving whenever it is in view, as its ground truth says; the camera's car brakes (2 s,
// evenly) to a stop GAP m before the bus's line as the bus's front enters its lane, waits until
// the bus has cleared the lane and pulls away (2 s) back to its speed. The stop starts at
// 35-45 % of the drive. The lead car turns right into the cross street's near lane (3.5 m short
// of the bus's line) before the camera stops, so the two never meet. Drives shorter than 8 s have
// no stop (the bus crosses beyond the end of the drive at mid-drive).
struct Crossing {
  double speed = 10.0;                             // the camera's cruising speed, m/s
  double ramp_s = 2.0;                             // braking and pulling away
  double t_stop = 1e9, t_go = 1e9;                 // s
  double x_bus = 0.0;      // the bus's line (world x)
  double t_mid = 0.0;      // s, when the bus's middle is on the camera's lane centre (y = -1.75)
  double bus_speed = 3.0;  // m/s, along +y
  double t_brake() const { return t_stop - ramp_s; }  // braking starts
  double x_street() const { return x_bus - 1.75; }  // the cross street's middle
  double x_turn() const { return x_bus - 3.5; }     // where the lead car turns
  // Distance the camera has driven along x at time t.
  double CameraX(double t) const {
    if (t <= t_brake()) return speed * t;
    const double x_stop = speed * (t_brake() + 0.5 * ramp_s);
    if (t <= t_stop) {
      const double tau = t - t_brake();
      return speed * (t_brake() + tau - tau * tau / (2 * ramp_s));
    }
    if (t <= t_go) return x_stop;
    const double tau = t - t_go;
    if (tau <= ramp_s) return x_stop + speed * tau * tau / (2 * ramp_s);
    return x_stop + speed * (0.5 * ramp_s + tau - ramp_s);
  }
  // The bus's middle along y at time t.
  double BusY(double t) const { return -1.75 + bus_speed * (t - t_mid); }
};

// The crossing vehicle's length: bus.jpg's bus is a minibus ("Un minibús 100% eléctrico" on its
// side), 6.5 x 3.2 m; without a bus photo, a car 4.5 m long.
double BusLength(bool bus) { return bus ? 6.5 : 4.5; }

Crossing PlanCrossing(uint64_t seed, double camera_speed, double duration, double bus_length_m) {
  Rng rng(seed);
  Crossing crossing;
  crossing.speed = camera_speed;
  const double stop_at = rng.Uniform(0.35, 0.45) * duration;
  const double gap = rng.Uniform(6.5, 8.0);
  crossing.bus_speed = rng.Uniform(2.5, 3.5);
  // The bus's front (half a length ahead of its middle) enters the lane (its right edge, y = -3.5)
  // 0.0-0.5 s after the camera has stopped.
  const double front_in = rng.Uniform(0.0, 0.5);
  if (duration >= 8.0) {
    crossing.t_stop = stop_at;
    crossing.x_bus = crossing.CameraX(stop_at) + gap;
    crossing.t_mid = stop_at + front_in + (1.75 + 0.5 * bus_length_m) / crossing.bus_speed;
    // Clear of the camera's lane (its rear 1 m past the lane's middle), then 0.3 s.
    const double clear_y = -1.75 + 1.0 + 0.5 * bus_length_m;
    crossing.t_go = crossing.t_mid + (clear_y + 1.75) / crossing.bus_speed + 0.3;
  } else {
    crossing.x_bus = camera_speed * duration + 2 * gap;
    crossing.t_mid = 0.5 * duration;
  }
  return crossing;
}

// Adds the crossing bus and removes the buildings and parked cars in the cross street (16 m wide).
void AddCrossingBus(Scene& scene, const ActorPhotos& photos, const Crossing& crossing) {
  const double half_street = 8.0;
  // Buildings (static structure above the ground) overlapping it, and every part of a parked car
  // whose body is in it.
  auto in_cross_street = [&](const Box& box) {
    const Eigen::Vector3d c = box.world_from_box.translation();
    if (std::abs(c.y()) < 5.0 || c.z() < 0.5) return false;  // road, sidewalks, lawns, wheels
    const double half_x = box.object_id == 0 ? box.half_extents.x() : 2.5;
    return std::abs(c.x() - crossing.x_street()) < half_street + half_x;
  };
  std::vector<int> removed_objects;
  for (const Box& box : scene.static_boxes)
    if (box.object_id != 0 && in_cross_street(box)) removed_objects.push_back(box.object_id);
  std::vector<Box> kept;
  kept.reserve(scene.static_boxes.size());
  for (const Box& box : scene.static_boxes) {
    const bool removed_object =
        box.object_id != 0 && std::find(removed_objects.begin(), removed_objects.end(),
                                        box.object_id) != removed_objects.end();
    if (!removed_object && !(box.object_id == 0 && in_cross_street(box))) kept.push_back(box);
  }
  scene.static_boxes = std::move(kept);
  const bool bus = !photos.buses.empty();
  const PhotoCutout& cutout = bus ? photos.buses[0] : photos.cars[0];
  // A bus photo is seldom broadside (bus.jpg's is seen from the front quarter, 1.6:1): stretched
  // to the bus's side, and mirrored (the quad's u axis runs right to left as the camera sees it
  // here) so its lettering reads. Measured on street seed 1 (docs/synth.md): YOLOX-nano finds this
  // bus on 0.82 of the frames 20-120 that show it, a 10 m stretch on 0.49 and, unmirrored, 0.32.
  PhotoCutout side = cutout;
  const double length_m = BusLength(bus), height_m = bus ? 3.2 : 1.5;
  const int width_px = static_cast<int>(std::lround(length_m / height_m * cutout.bgr.rows));
  if (width_px > cutout.bgr.cols) {
    cv::resize(cutout.bgr, side.bgr, cv::Size(width_px, cutout.bgr.rows), 0, 0, cv::INTER_LINEAR);
    cv::resize(cutout.alpha, side.alpha, cv::Size(width_px, cutout.alpha.rows), 0, 0,
               cv::INTER_NEAREST);
  }
  cv::flip(side.bgr, side.bgr, 1);
  cv::flip(side.alpha, side.alpha, 1);
  const int sprite = AddSprite(scene, side, height_m);
  const int id = scene.AddObject(bus ? "bus-crossing" : "car-crossing", bus ? 5 : 2, true);
  scene.objects[id - 1].appearance = cutout.source;
  const double w = scene.sprites[sprite].width_m(), h = scene.sprites[sprite].height_m();
  scene.actors.push_back([=](double t, std::vector<Box>& boxes) {
    AppendSprite(At(crossing.x_bus, crossing.BusY(t), 0, M_PI / 2), 0.0, sprite, w, h, id, boxes);
  });
}

void BuildStreet(const SceneOptions& options, const ActorPhotos* photos, Scene& scene) {
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
  // With photos, moving cars are photo cut-outs 1.5 m tall whose quad spans the road (seen
  // from behind or ahead); the draws for the box car are made anyway, so the rest of the scene
  // does not change.
  // The intersection's plan (photos only; its own stream).
  const Crossing crossing = PlanCrossing(SubSeed(options.seed, 0xB05), speed, duration,
                                        BusLength(photos && !photos->buses.empty()));
  int photo_cars = 0;
  auto driving_car = [&](const Rigid3d& world_from_body_at_0, double car_speed,
                         const CarLook& look, int id) {
    if (!photos) return MakeDrivingCar(world_from_body_at_0, car_speed, look, id);
    const PhotoCutout& cutout = photos->cars[photo_cars++ % photos->cars.size()];
    const int sprite = AddSprite(scene, cutout, 1.5);
    scene.objects[id - 1].appearance = cutout.source;
    return MakeDrivingSprite(world_from_body_at_0, car_speed, M_PI / 2, sprite,
                             scene.sprites[sprite].width_m(), scene.sprites[sprite].height_m(), id);
  };
  // Moving cars: one leading in the camera's lane, oncoming ones passing at spread-out times.
  {
    const int id = scene.AddObject("car-lead", 2, true);
    // Same argument expressions as the box car had: the draws keep their (compiler's) order.
    scene.actors.push_back(driving_car(At(rng.Uniform(15, 22), -1.75, 0),
                                       speed * rng.Uniform(0.9, 1.05), car_look(), id));
    if (photos) {
      // With photos the lead car follows close, 8-12 m ahead at the camera's speed (the gap
      // swinging slowly): static in the image, so only the detector can flag it, and large
      // (~110 x 270 px at 10 m). At the intersection it turns right into the cross street
      // (6 m/s along -y; its quad already faces the camera broadside). Own stream. Its photo is
      // the second car cut-out (dog.jpg's pickup from ../shared/images): YOLOX-nano finds it on
      // 41 of the first 50 frames of seed 1, street.png's taxi (the first) on 4.
      Rng follow(SubSeed(options.seed, 0xF011));
      const double gap = follow.Uniform(9.5, 10.5), swing = follow.Uniform(1.0, 1.5);
      const double period = follow.Uniform(6.0, 10.0), phase = follow.Uniform(0, 2 * M_PI);
      auto lead_x = [=](double t) {
        return speed * t + gap + swing * std::sin(2 * M_PI * t / period + phase);
      };
      // lead_x rises monotonically (speed > swing's rate): bisect for the turn.
      const double x_turn = crossing.x_turn();
      double lo = 0.0, hi = duration + 10.0;
      for (int i = 0; i < 60; ++i) ((lead_x(0.5 * (lo + hi)) < x_turn) ? lo : hi) = 0.5 * (lo + hi);
      const double t_turn = lead_x(0.0) < x_turn ? lo : 0.0;
      const PhotoCutout& cutout = photos->cars[std::min<size_t>(1, photos->cars.size() - 1)];
      const int sprite = AddSprite(scene, cutout, 1.5);
      scene.objects[id - 1].appearance = cutout.source;
      const double w = scene.sprites[sprite].width_m(), h = scene.sprites[sprite].height_m();
      scene.actors.back() = [=](double t, std::vector<Box>& boxes) {
        const Eigen::Vector3d at = t < t_turn
                                       ? Eigen::Vector3d(lead_x(t), -1.75, 0)
                                       : Eigen::Vector3d(x_turn, -1.75 - 6.0 * (t - t_turn), 0);
        AppendSprite(At(at.x(), at.y(), 0), M_PI / 2, sprite, w, h, id, boxes);
      };
    }
  }
  const int oncoming = 2 + static_cast<int>(rng.Next() % 2);
  for (int i = 0; i < oncoming; ++i) {
    const double car_speed = rng.Uniform(8, 12);
    const double pass_time = (i + rng.Uniform(0.3, 0.9)) * std::max(duration, 4.0) / oncoming;
    // Passing the camera (x = speed * pass_time) at pass_time.
    const double x0 = speed * pass_time + car_speed * pass_time;
    const int id = scene.AddObject("car-oncoming-" + std::to_string(i + 1), 2, true);
    scene.actors.push_back(driving_car(At(x0, 1.75, 0, M_PI), car_speed, car_look(), id));
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
    const PersonLook look = MakePersonLook(textures, rng, 1.0);
    // With photos: a quad across the sidewalk (the camera driving along the road sees the
    // figure's front).
    AddWalker(scene, path, look, id,
              photos ? &photos->persons[3 % photos->persons.size()] : nullptr, 1.75, M_PI / 2);
  }
  if (photos) {
    // Movers of no COCO class: a crate wheeled along the left sidewalk towards the camera, and
    // a cube tumbling along the right bike lane.
    Rng decoy(SubSeed(options.seed, 0xDEC2));
    TextureMaker decoy_textures(scene, SubSeed(options.seed, 0xDEC3));
    BackAndForthPath crate_path;
    crate_path.a = {decoy.Uniform(40, 60), 8.3, 0};
    crate_path.b = {-30, 8.3, 0};
    crate_path.speed = decoy.Uniform(1.2, 1.8);
    const Eigen::Vector3d crate_half(0.45, 0.4, 0.55);
    AddTumblingBox(
        scene, "crate", crate_path, crate_half.z(), crate_half, Eigen::Vector3d::UnitZ(), 0.0,
        decoy_textures.ForBox(TextureStyle::kWood, crate_half, 0.01, RandomTint(decoy)));
    BackAndForthPath cube_path;
    cube_path.a = {decoy.Uniform(20, 35), -4.3, 0};
    cube_path.b = {cube_path.a.x() + 400.0, -4.3, 0};
    cube_path.speed = decoy.Uniform(2.5, 4.0);
    const Eigen::Vector3d cube_half(0.4, 0.4, 0.4);
    AddTumblingBox(
        scene, "tumbling-cube", cube_path, 0.7, cube_half, Eigen::Vector3d(0.2, 1.0, 0.1), 2.0,
        decoy_textures.ForBox(TextureStyle::kCloth, cube_half, 0.01, RandomTint(decoy)));
    AddCrossingBus(scene, *photos, crossing);
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
  if (photos) {
    // The stop at the intersection: the same road, driven on the crossing's time table.
    scene.world_from_cam = [drive = scene.world_from_cam, crossing](double t) {
      return drive(crossing.CameraX(t) / crossing.speed);
    };
  }
}

// The street's loop: a ring road (the camera in the outer lane, counter-clockwise at about
// 10 m/s, one lap in 85 % of the sequence) lined with facades on both sides and parked cars; no
// moving objects. Same camera as the street.
void BuildStreetLoop(const SceneOptions& options, Scene& scene) {
  Rng rng(SubSeed(options.seed, 0x100B));
  TextureMaker textures(scene, SubSeed(options.seed, 0x7E89));
  scene.fps = 10.0;
  Camera camera;
  camera.width = 1241, camera.height = 376;
  camera.fx = camera.fy = 718.856;
  camera.cx = 607.1928, camera.cy = 185.2157;
  scene.camera = ScaledCamera(camera, options.width, options.height);
  scene.sky_bgr = {235.f, 205.f, 170.f};

  const double period = LoopPeriod(options, scene.fps);
  const double camera_radius = std::max(25.0, 10.0 * period / (2 * M_PI));
  const double axis = camera_radius - 1.75;  // road centre line; the camera in the outer lane
  // A pose on the ring at `angle`, `offset` metres outwards from the road axis, box x along the
  // road.
  auto on_ring = [&](double angle, double offset, double z) {
    const double r = axis + offset;
    return At(r * std::cos(angle), r * std::sin(angle), z, angle + M_PI / 2);
  };
  const double ground = axis + 70.0;
  scene.static_boxes.push_back(MakeBox(
      At(0, 0, -0.11), {ground, ground, 0.05},
      textures.Make(TextureStyle::kFloor, 2 * ground, 2 * ground, 0.2, {0.45f, 0.8f, 0.55f})));
  const int segments = static_cast<int>(std::ceil(2 * M_PI * axis / 10.0));
  const double step = 2 * M_PI / segments;
  for (int k = 0; k < segments; ++k) {
    const double angle = k * step;
    // Slightly longer than the chord at the outer edge so the polygon has no gaps.
    const double length = 2 * (axis + 11.0) * std::sin(step / 2) + 0.2;
    scene.static_boxes.push_back(MakeBox(on_ring(angle, 0, -0.05), {length / 2, 7.0, 0.05},
                                         textures.Make(TextureStyle::kRoad, length, 14.0, 0.02)));
    for (int side : {-1, 1}) {
      scene.static_boxes.push_back(MakeBox(
          on_ring(angle, 9.0 * side, 0.075), {length / 2, 2.0, 0.075},
          textures.Make(TextureStyle::kSidewalk, length, 4.0, 0.02, {0.85f, 0.9f, 0.95f})));
    }
  }
  // Facades along both sides, 11-15 m from the road axis (inside only where the ring leaves room).
  for (int side : {-1, 1}) {
    double arc = rng.Uniform(0, 5);
    const double circumference = 2 * M_PI * axis;
    while (arc < circumference - 8) {
      const double length = std::min(rng.Uniform(8, 20), circumference - arc - 2);
      const double height = rng.Uniform(8, 25), depth = 10.0;
      const double setback = 11.0 + rng.Uniform(0, 4);
      const double offset = side * (setback + depth / 2);
      if (axis + offset - depth / 2 > 3.0) {
        Box building = MakeBox(on_ring((arc + length / 2) / axis, offset, height / 2),
                               {length / 2, depth / 2, height / 2}, 0);
        const cv::Vec3f tint = RandomTint(rng, 0.6f, 1.1f);
        const int front = textures.Make(TextureStyle::kFacade, length, height, 0.05, tint);
        const int ends = textures.Make(TextureStyle::kFacade, depth, height, 0.05, tint);
        building.face_texture = {ends, ends, front, front, front, front};
        scene.static_boxes.push_back(building);
      }
      arc += length + (rng.Uniform() < 0.5 ? 0.5 : rng.Uniform(2, 6));
    }
  }
  // Parked cars in the parking lanes, heading either way.
  int parked = 0;
  for (int side : {-1, 1}) {
    for (double arc = rng.Uniform(0, 10); arc < 2 * M_PI * axis - 10; arc += rng.Uniform(8, 25)) {
      if (rng.Uniform() < 0.3) continue;
      CarLook look;
      look.paint = textures.ForBox(TextureStyle::kCarPaint, {2.1, 2.1, 2.1}, 0.01,
                                   RandomTint(rng, 0.3f, 1.2f));
      look.glass = textures.ForBox(TextureStyle::kDark, {1.1, 1.1, 1.1}, 0.01);
      look.tyre =
          textures.ForBox(TextureStyle::kDark, {0.93, 0.93, 0.93}, 0.01, {0.8f, 0.8f, 0.8f});
      Rigid3d pose = on_ring(arc / axis, 5.6 * side, 0);
      if (rng.Uniform() < 0.5)
        pose.linear() =
            pose.linear() * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      const int id = scene.AddObject("parked-car-" + std::to_string(++parked), 2, false);
      AppendCar(pose, look, id, scene.static_boxes);
    }
  }

  MotionSpec motion;
  motion.kind = MotionKind::kLoop;
  motion.loop_centre = {0, 0, 1.65};
  motion.loop_radii = {camera_radius, camera_radius};
  motion.loop_period_s = period;
  motion.loop_start_rad = 0.0;
  motion.loop_look_ahead = true;
  motion.loop_pitch_rad = 0.0;
  motion.jitter_translation_m = 0.01;
  motion.jitter_rotation_rad = 0.002;
  motion.seed = SubSeed(options.seed, 0xCA5);
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
  std::optional<ActorPhotos> photos;
  if (!options.actor_photos.empty()) photos = LoadActorPhotos(options.actor_photos);
  const ActorPhotos* photos_ptr = photos ? &*photos : nullptr;
  if (options.scene == "office") {
    BuildOffice(options, photos_ptr, scene);
  } else if (options.motion == MotionKind::kLoop) {
    BuildStreetLoop(options, scene);
  } else {
    BuildStreet(options, photos_ptr, scene);
  }
  return scene;
}

}  // namespace ademono::synth
