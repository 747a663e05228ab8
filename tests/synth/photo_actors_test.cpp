// Photo-textured actors: sprite quads in the renderer, cut-outs from a photo folder, and the
// office with photo persons and movers of no COCO class. The photos are drawn here (a magenta
// figure and a blue car on green), so the test needs no ../shared and knows every colour.
#include <unistd.h>
#include <string>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "ademono/core/error.h"
#include "ademono/synth/generator.h"
#include "ademono/synth/photos.h"
#include "ademono/synth/renderer.h"

namespace ademono::synth {
namespace {

namespace fs = std::filesystem;

bool Magenta(const cv::Vec3b& c) { return c[0] > 200 && c[1] < 60 && c[2] > 200; }

// A photo folder: one picture with a magenta person (ellipse body, round head), a blue car and a
// yellow bus on a green background, and its expected_detections.json.
fs::path MakePhotoFolder(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("ademono_photos_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  cv::Mat image(400, 700, CV_8UC3, cv::Scalar(0, 160, 0));
  cv::ellipse(image, cv::Point(120, 230), cv::Size(45, 130), 0, 0, 360, cv::Scalar(255, 0, 255),
              cv::FILLED);
  cv::circle(image, cv::Point(120, 80), 30, cv::Scalar(255, 0, 255), cv::FILLED);
  cv::rectangle(image, cv::Rect(250, 250, 200, 80), cv::Scalar(255, 0, 0), cv::FILLED);
  cv::rectangle(image, cv::Rect(500, 100, 180, 120), cv::Scalar(0, 230, 255), cv::FILLED);
  cv::imwrite((dir / "scene.png").string(), image);
  nlohmann::json json;
  json["images"]["scene.png"]["detections"] = {
      {{"class_id", 0}, {"class", "person"}, {"score", 0.9}, {"box_xywh", {70, 45, 100, 320}}},
      {{"class_id", 2}, {"class", "car"}, {"score", 0.8}, {"box_xywh", {245, 245, 210, 90}}},
      {{"class_id", 5}, {"class", "bus"}, {"score", 0.85}, {"box_xywh", {495, 95, 190, 130}}},
      // Too small / too unsure to use.
      {{"class_id", 0}, {"class", "person"}, {"score", 0.2}, {"box_xywh", {300, 20, 50, 150}}}};
  std::ofstream(dir / "expected_detections.json") << json.dump();
  return dir;
}

std::string FileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(PhotoActors, SpriteQuadHasExactDepthAndAlphaSilhouette) {
  Camera camera;
  camera.width = 120, camera.height = 100;
  camera.fx = camera.fy = 100.0;
  camera.cx = 59.5, camera.cy = 49.5;
  TextureSpec spec;
  spec.width_m = 8, spec.height_m = 8, spec.texel_m = 0.02;
  const std::vector<Texture> textures{Texture::Generate(spec)};
  // A 1 x 1 m sprite, opaque on its left half, uniform orange.
  cv::Mat bgr(100, 100, CV_8UC3, cv::Scalar(0, 128, 255));
  cv::Mat alpha(100, 100, CV_8UC1, cv::Scalar(0));
  alpha(cv::Rect(0, 0, 50, 100)).setTo(255);
  const std::vector<Sprite> sprites{Sprite::FromCutout(bgr, alpha, 1.0)};
  Box room = MakeBox(Rigid3d::Identity(), {4, 4, 4}, 0);
  room.inside = true;
  // The quad spans the box's x and z; turned so that it faces the camera (looking along +z):
  // box x = camera x, box z = -camera y, box y = camera z; centred 2 m ahead.
  Rigid3d world_from_quad = Rigid3d::Identity();
  world_from_quad.linear() << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  world_from_quad.translation() = Eigen::Vector3d(0, 0, 2);
  Box quad = MakeBox(world_from_quad, {0.5, 0.005, 0.5}, 0, 7);
  quad.sprite = 0;
  const RenderedFrame frame =
      RenderBoxes(camera, textures, {room, quad}, Rigid3d::Identity(), {0, 0, 0}, sprites);
  int on = 0;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const double x = (u - camera.cx) / camera.fx * 2.0, y = (v - camera.cy) / camera.fy * 2.0;
      const bool inside = std::abs(y) < 0.49 && x > -0.49 && x < -0.01;
      const bool outside = std::abs(y) > 0.51 || x < -0.51 || x > 0.01;
      const int id = frame.object_id.at<int32_t>(v, u);
      if (inside) {
        ++on;
        EXPECT_EQ(id, 7) << u << "," << v;
        EXPECT_NEAR(frame.depth.at<float>(v, u), 2.0f, 1e-5);
        EXPECT_EQ(frame.image.at<cv::Vec3b>(v, u), cv::Vec3b(0, 128, 255));  // unshaded photo
      } else if (outside) {
        EXPECT_EQ(id, 0) << u << "," << v;  // transparent texels show the room
        EXPECT_FLOAT_EQ(frame.depth.at<float>(v, u), 4.0f);
      }
    }
  }
  EXPECT_GT(on, 1000);
  Box bad = quad;
  bad.sprite = 1;
  EXPECT_THROW(RenderBoxes(camera, textures, {bad}, Rigid3d::Identity(), {0, 0, 0}, sprites),
               std::invalid_argument);
}

TEST(PhotoActors, CutOutsFollowTheFigureAndBadFoldersFail) {
  const fs::path dir = MakePhotoFolder("cutouts");
  const ActorPhotos photos = LoadActorPhotos(dir);
  ASSERT_EQ(photos.persons.size(), 1u);  // the unsure one is left out
  ASSERT_EQ(photos.cars.size(), 1u);
  ASSERT_EQ(photos.buses.size(), 1u);
  EXPECT_EQ(photos.buses[0].source, "scene.png#3");
  EXPECT_NEAR(photos.buses[0].alpha.cols, 181, 3);
  EXPECT_NEAR(photos.buses[0].alpha.rows, 121, 3);
  const PhotoCutout& person = photos.persons[0];
  EXPECT_EQ(person.source, "scene.png#1");
  // Tight around the drawn figure (head top 50, body bottom 360, body 90 wide), within 3 px.
  EXPECT_NEAR(person.alpha.rows, 311, 3);
  EXPECT_NEAR(person.alpha.cols, 91, 3);
  int figure = 0, figure_opaque = 0, green_opaque = 0;
  for (int v = 0; v < person.bgr.rows; ++v) {
    for (int u = 0; u < person.bgr.cols; ++u) {
      const bool opaque = person.alpha.at<uint8_t>(v, u) >= 128;
      if (Magenta(person.bgr.at<cv::Vec3b>(v, u))) {
        ++figure;
        figure_opaque += opaque;
      } else {
        green_opaque += opaque;
      }
    }
  }
  EXPECT_GE(figure_opaque, 0.99 * figure);
  EXPECT_LE(green_opaque, 0.02 * figure);
  EXPECT_NEAR(photos.cars[0].alpha.cols, 201, 3);
  EXPECT_NEAR(photos.cars[0].alpha.rows, 81, 3);

  EXPECT_THROW(LoadActorPhotos(dir / "missing"), InputError);
  fs::remove(dir / "scene.png");
  EXPECT_THROW(LoadActorPhotos(dir), InputError);
  std::ofstream(dir / "expected_detections.json") << "{\"images\": {}}";
  EXPECT_THROW(LoadActorPhotos(dir), InputError);  // no person to cut out
  fs::remove_all(dir);
}

TEST(PhotoActors, OfficeWithPhotosIsDeterministicAndMasksMatchPixels) {
  const fs::path photos = MakePhotoFolder("office");
  const fs::path root =
      fs::temp_directory_path() / ("ademono_photo_office_" + std::to_string(::getpid()));
  fs::remove_all(root);
  GeneratorOptions options;
  options.scene.scene = "office";
  options.scene.frames = 3;
  options.scene.seed = 4;
  options.scene.width = 256, options.scene.height = 192;
  options.scene.persons = 3;
  options.scene.actor_photos = photos.string();
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  GenerateSequence(options, root / "a");
  cv::setNumThreads(4);
  GenerateSequence(options, root / "b");
  cv::setNumThreads(threads);
  for (const auto& entry : fs::recursive_directory_iterator(root / "a")) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), root / "a");
    EXPECT_EQ(FileBytes(entry.path()), FileBytes(root / "b" / rel)) << rel;
  }
  EXPECT_TRUE(fs::exists(root / "a" / "objects.jsonl"));

  const Scene scene = BuildScene(options.scene);
  EXPECT_EQ(scene.sprites.size(), 3u);
  std::vector<int> photo_ids, decoy_ids;
  for (const SceneObject& o : scene.objects) {
    if (!o.appearance.empty()) photo_ids.push_back(o.id);
    if (o.class_id < 0) decoy_ids.push_back(o.id);
  }
  ASSERT_EQ(photo_ids.size(), 3u);
  ASSERT_EQ(decoy_ids.size(), 2u);
  // Over a second of walking, sampled: photo pixels are the figure's magenta, nothing else is
  // magenta, photo persons and the decoys are in the moving mask, and the decoys never get a box.
  long long photo_pixels = 0, photo_magenta = 0, decoy_pixels = 0;
  for (size_t i = 0; i < 60; i += 6) {
    const RenderedFrame frame = RenderSceneFrame(scene, i, options);
    const cv::Mat mask = MovingMask(scene, frame.object_id);
    for (int v = 0; v < frame.image.rows; ++v) {
      for (int u = 0; u < frame.image.cols; ++u) {
        const int id = frame.object_id.at<int32_t>(v, u);
        const bool photo = std::find(photo_ids.begin(), photo_ids.end(), id) != photo_ids.end();
        const bool decoy = std::find(decoy_ids.begin(), decoy_ids.end(), id) != decoy_ids.end();
        const bool magenta = Magenta(frame.image.at<cv::Vec3b>(v, u));
        if (photo) {
          ++photo_pixels;
          photo_magenta += magenta;
        } else {
          ASSERT_FALSE(magenta) << "frame " << i << " pixel " << u << "," << v;
        }
        decoy_pixels += decoy;
        if (photo || decoy) {
          ASSERT_EQ(mask.at<uint8_t>(v, u), 255);
        }
      }
    }
    const std::vector<Detection> boxes = BoxesFromObjectIds(scene, frame.object_id, 16);
    const std::vector<ObjectExtent> extents = ObjectExtents(scene, frame.object_id);
    size_t expected_boxes = 0;
    for (const SceneObject& o : scene.objects)
      expected_boxes += o.class_id >= 0 && extents[o.id - 1].pixels >= 16;
    EXPECT_EQ(boxes.size(), expected_boxes);
  }
  EXPECT_GT(photo_pixels, 5000);
  // Bilinear sampling blends the figure's edge texels with the photo's green.
  EXPECT_GE(photo_magenta, 0.9 * photo_pixels);
  EXPECT_GT(decoy_pixels, 100);
  fs::remove_all(root);
  fs::remove_all(photos);
}

// The street's photo movers that matter (issue 17): a lead car close ahead in the camera's lane,
// static in the image until it turns off at the intersection, and a bus crossing the road there,
// broadside and large. Both come from the same hit test as every other object: visible, in the
// moving mask, with a box of their class; the box-only street has neither.
TEST(PhotoActors, StreetHasACloseLeadCarAndABusCrossingTheIntersection) {
  const fs::path photos = MakePhotoFolder("street");
  GeneratorOptions options;
  options.scene.scene = "street";
  options.scene.frames = 150;
  options.scene.seed = 1;
  options.scene.width = 310, options.scene.height = 94;  // a quarter of KITTI's size
  options.scene.actor_photos = photos.string();
  const Scene scene = BuildScene(options.scene);
  int bus_id = 0, lead_id = 0;
  for (const SceneObject& o : scene.objects) {
    if (o.name == "bus-crossing") bus_id = o.id;
    if (o.name == "car-lead") lead_id = o.id;
  }
  ASSERT_GT(bus_id, 0);
  ASSERT_GT(lead_id, 0);
  const SceneObject& bus = scene.objects[bus_id - 1];
  EXPECT_EQ(bus.class_name, "bus");
  EXPECT_TRUE(bus.moving);
  EXPECT_EQ(bus.appearance, "scene.png#3");
  EXPECT_TRUE(scene.objects[lead_id - 1].moving);

  const double image_pixels = options.scene.width * options.scene.height;
  int lead_frames = 0, lead_still = 0, bus_frames = 0, bus_large = 0;
  double lead_min_depth = 1e9, lead_max_depth = 0.0, bus_min_depth = 1e9, bus_max_share = 0.0;
  cv::Point2d lead_last(-100, -100);
  for (size_t i = 0; i < options.scene.frames; i += 2) {
    const RenderedFrame frame = RenderSceneFrame(scene, i, options);
    const cv::Mat mask = MovingMask(scene, frame.object_id);
    const std::vector<ObjectExtent> extents = ObjectExtents(scene, frame.object_id);
    const std::vector<Detection> boxes = BoxesFromObjectIds(scene, frame.object_id, 16);
    auto has_box = [&](const ObjectExtent& e, const std::string& cls) {
      for (const Detection& d : boxes)
        if (d.class_name == cls && std::abs(d.box.x - e.umin) <= 1 &&
            std::abs(d.box.y - e.vmin) <= 1)
          return true;
      return false;
    };
    double lead_depth = 0.0, bus_depth = 1e9;
    for (int v = 0; v < frame.object_id.rows; ++v) {
      for (int u = 0; u < frame.object_id.cols; ++u) {
        const int id = frame.object_id.at<int32_t>(v, u);
        if (id != bus_id && id != lead_id) continue;
        ASSERT_EQ(mask.at<uint8_t>(v, u), 255) << "frame " << i;
        const double z = frame.depth.at<float>(v, u);
        if (id == lead_id) lead_depth = std::max(lead_depth, z);
        if (id == bus_id) bus_depth = std::min(bus_depth, z);
      }
    }
    const ObjectExtent& lead = extents[lead_id - 1];
    if (lead.pixels >= 16) {
      ++lead_frames;
      EXPECT_TRUE(has_box(lead, "car")) << "frame " << i;
      const cv::Point2d centre(0.5 * (lead.umin + lead.umax), 0.5 * (lead.vmin + lead.vmax));
      // Following: its box centre stays within a few pixels between samples (0.2 s).
      const bool still = cv::norm(centre - lead_last) <= 3.0;
      lead_still += still;
      lead_last = centre;
      if (still) {
        EXPECT_GT(lead.pixels, 0.02 * image_pixels) << "frame " << i;
        lead_min_depth = std::min(lead_min_depth, lead_depth);
        lead_max_depth = std::max(lead_max_depth, lead_depth);
      }
    }
    const ObjectExtent& b = extents[bus_id - 1];
    if (b.pixels >= 16) {
      ++bus_frames;
      EXPECT_TRUE(has_box(b, "bus")) << "frame " << i;
      const double share = b.pixels / image_pixels;
      bus_max_share = std::max(bus_max_share, share);
      if (share > 0.05) {
        ++bus_large;
        bus_min_depth = std::min(bus_min_depth, bus_depth);
      }
    }
  }
  // The lead car is in view until the intersection (35-45 % of the drive), still in the image
  // but for its turn, and then 8-12 m ahead (its farthest pixel: the quad is upright, facing the
  // camera).
  EXPECT_GE(lead_frames, 25);
  EXPECT_GE(lead_still, 18);
  EXPECT_GE(lead_min_depth, 7.5);
  EXPECT_LE(lead_max_depth, 12.5);
  // The bus covers over 5 % of the image for seconds (every other frame sampled) and over a
  // third of it at best, never closer than 5 m (the camera waits 6.5-8 m before its line, and
  // pulls away when the bus's rear has cleared its lane).
  EXPECT_GE(bus_frames, 10);
  EXPECT_GE(bus_large, 8);
  EXPECT_GE(bus_max_share, 0.33);
  EXPECT_GE(bus_min_depth, 5.0);
  // The camera stops for the bus (until it has cleared the lane: 2.9-4.5 s) and drives on; on the
  // box-only street it never stops.
  int still_frames = 0;
  for (size_t i = 1; i < options.scene.frames; ++i)
    still_frames += (scene.world_from_cam(scene.TimeOf(i)).translation() -
                     scene.world_from_cam(scene.TimeOf(i - 1)).translation())
                        .norm() < 1e-9;
  EXPECT_GE(still_frames, 28);
  EXPECT_LE(still_frames, 46);
  EXPECT_GT(scene.world_from_cam(scene.TimeOf(149)).translation().x(), 80.0);

  // Without photos the street has neither (and stays the box street).
  SceneOptions boxes_only = options.scene;
  boxes_only.actor_photos.clear();
  const Scene box_street = BuildScene(boxes_only);
  for (const SceneObject& o : box_street.objects)
    EXPECT_TRUE(o.name != "bus-crossing" && o.class_id != 5) << o.name;
  for (size_t i = 1; i < options.scene.frames; ++i)
    EXPECT_GT((box_street.world_from_cam(box_street.TimeOf(i)).translation() -
               box_street.world_from_cam(box_street.TimeOf(i - 1)).translation())
                  .norm(),
              0.9);
  fs::remove_all(photos);
}

}  // namespace
}  // namespace ademono::synth
