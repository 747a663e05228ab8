#pragma once
// A synthetic scene: textured boxes (static structure plus articulated moving actors), the
// objects the ground truth talks about, the camera and its trajectory.
//
// Conventions: world frame z up; boxes are oriented boxes with their frame at the centre; every
// pose is named b_from_a as in core/geometry.h. Object id 0 is static structure (walls, ground,
// furniture, buildings); ids >= 1 index Scene::objects (persons, cars, bicycles, ...).

#include <Eigen/Core>
#include <array>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "ademono/core/camera.h"
#include "ademono/core/geometry.h"
#include "ademono/synth/sprite.h"
#include "ademono/synth/texture.h"

namespace ademono::synth {

struct Box {
  Rigid3d world_from_box = Rigid3d::Identity();
  Eigen::Vector3d half_extents{0.5, 0.5, 0.5};
  // Texture per face, index into Scene::textures, faces in order -x, +x, -y, +y, -z, +z.
  std::array<int, 6> face_texture{0, 0, 0, 0, 0, 0};
  int object_id = 0;
  // Seen from inside (a room): the surface is where the ray leaves the box.
  bool inside = false;
  // >= 0: not a box but the photo sprite Scene::sprites[sprite] on the quad through the centre
  // spanning the box's x and z axes (synth/sprite.h); face_texture is then unused.
  int sprite = -1;
};

struct SceneObject {
  int id = 0;
  std::string name;        // "person-1", "mannequin", "car-3", ...
  int class_id = -1;       // COCO class id
  std::string class_name;  // COCO class name
  bool moving = false;     // true when the object moves during the sequence
  std::string appearance;  // empty: procedural boxes; else the photo it is cut from
};

// Appends the boxes of one animated actor at time t (seconds) to `boxes`.
using ActorFunction = std::function<void(double t, std::vector<Box>& boxes)>;

struct Scene {
  std::string name;  // "office" or "street"
  Camera camera;
  double fps = 30.0;
  std::vector<Texture> textures;
  std::vector<Sprite> sprites;  // photo cut-outs (only with actor photos)
  std::vector<Box> static_boxes;
  std::vector<SceneObject> objects;  // objects[i].id == i + 1
  std::vector<ActorFunction> actors;
  std::function<Rigid3d(double t)> world_from_cam;  // camera trajectory
  cv::Vec3f sky_bgr{235.f, 200.f, 160.f};           // colour where no surface is hit (depth 0)

  // Static and animated boxes at time t.
  std::vector<Box> BoxesAt(double t) const;
  double TimeOf(size_t frame) const { return static_cast<double>(frame) / fps; }

  // Adds a texture and returns its index.
  int AddTexture(const TextureSpec& spec);
  // Adds an object and returns its id. class_id -1: no COCO class (a mover no detector should
  // name; it is in the moving masks but never in detections.jsonl).
  int AddObject(const std::string& name, int class_id, bool moving);
};

// A box with one texture on every face.
Box MakeBox(const Rigid3d& world_from_box, const Eigen::Vector3d& half_extents, int texture,
            int object_id = 0);

}  // namespace ademono::synth
