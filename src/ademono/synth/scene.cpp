#include "ademono/synth/scene.h"

#include "ademono/perception/detection_io.h"

namespace ademono::synth {

std::vector<Box> Scene::BoxesAt(double t) const {
  std::vector<Box> boxes = static_boxes;
  for (const ActorFunction& actor : actors) actor(t, boxes);
  return boxes;
}

int Scene::AddTexture(const TextureSpec& spec) {
  textures.push_back(Texture::Generate(spec));
  return static_cast<int>(textures.size()) - 1;
}

int Scene::AddObject(const std::string& object_name, int class_id, bool moving) {
  SceneObject object;
  object.id = static_cast<int>(objects.size()) + 1;
  object.name = object_name;
  object.class_id = class_id;
  object.class_name = class_id < 0 ? "none" : CocoClassNames().at(class_id);
  object.moving = moving;
  objects.push_back(object);
  return object.id;
}

Box MakeBox(const Rigid3d& world_from_box, const Eigen::Vector3d& half_extents, int texture,
            int object_id) {
  Box box;
  box.world_from_box = world_from_box;
  box.half_extents = half_extents;
  box.face_texture.fill(texture);
  box.object_id = object_id;
  return box;
}

}  // namespace ademono::synth
