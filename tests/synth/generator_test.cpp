#include "ademono/synth/generator.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/io/sequence.h"
#include "ademono/io/trajectory.h"

namespace ademono::synth {
namespace {

namespace fs = std::filesystem;

class GeneratorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("ademono_synth_" + std::to_string(::getpid()) + "_" +
             std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  static GeneratorOptions SmallOffice(uint64_t seed) {
    GeneratorOptions options;
    options.scene.scene = "office";
    options.scene.frames = 4;
    options.scene.seed = seed;
    options.scene.width = 256;
    options.scene.height = 192;
    options.scene.persons = 3;
    return options;
  }

  fs::path root_;
};

std::string FileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::map<std::string, std::string> AllFiles(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.is_regular_file())
      files[fs::relative(entry.path(), dir).string()] = FileBytes(entry.path());
  return files;
}

// The written sequence reads back through the TUM reader: frame count, camera, depth values and
// ground-truth poses equal what was rendered.
TEST_F(GeneratorTest, RoundTripsThroughTumReader) {
  GeneratorOptions options = SmallOffice(3);
  options.scene.motion = MotionKind::kHalfsphere;
  const fs::path dir = root_ / "office";
  const GeneratorSummary summary = GenerateSequence(options, dir);
  EXPECT_EQ(summary.frames, 4u);

  const Scene scene = BuildScene(options.scene);
  const auto sequence = OpenSequence("tum:" + dir.string());
  ASSERT_EQ(sequence->Size(), 4u);
  EXPECT_TRUE(sequence->HasDepth());
  EXPECT_TRUE(sequence->HasGroundTruth());
  const Camera& camera = sequence->GetCamera();
  EXPECT_EQ(camera.width, 256);
  EXPECT_EQ(camera.height, 192);
  EXPECT_DOUBLE_EQ(camera.fx, 525.0 * 256 / 640);
  EXPECT_DOUBLE_EQ(camera.cx, scene.camera.cx);

  const Trajectory groundtruth = ReadTumTrajectory(dir / "groundtruth.txt");
  ASSERT_EQ(groundtruth.size(), 4u);
  for (size_t i = 0; i < sequence->Size(); ++i) {
    const FrameData frame = sequence->Load(i);
    EXPECT_NEAR(frame.timestamp, i / 30.0, 1e-6);
    ASSERT_EQ(frame.image.size(), cv::Size(256, 192));
    const RenderedFrame rendered = RenderSceneFrame(scene, i, options);
    EXPECT_EQ(cv::norm(frame.image, rendered.image, cv::NORM_INF), 0.0);
    // Depth: the rendered depth to PNG quantisation (the office is within the 13.1 m range).
    ASSERT_EQ(frame.depth.type(), CV_32FC1);
    cv::Mat difference;
    cv::absdiff(frame.depth, rendered.depth, difference);
    double max_difference = 0;
    cv::minMaxLoc(difference, nullptr, &max_difference);
    EXPECT_LE(max_difference, 0.5 / kDepthPngScale + 1e-6);
    EXPECT_EQ(cv::countNonZero(frame.depth), frame.depth.total())
        << "closed room: depth everywhere";
    // Poses.
    const Rigid3d expected = scene.world_from_cam(std::stod(FrameStamp(scene, i)));
    ASSERT_TRUE(frame.world_from_cam_gt.has_value());
    EXPECT_LT((frame.world_from_cam_gt->translation() - expected.translation()).norm(), 1e-6);
    EXPECT_LT(RotationAngle(frame.world_from_cam_gt->linear().transpose() * expected.linear()),
              1e-6);
    EXPECT_LT((groundtruth[i].world_from_cam.translation() - expected.translation()).norm(), 1e-6);
  }
}

// Static scene points seen in one frame land, through the ground-truth poses read back from
// groundtruth.txt, on pixels of a later frame whose depth is theirs: poses, depth and camera
// agree (up to the 0.2 mm PNG step and one-pixel rounding at depth edges).
TEST_F(GeneratorTest, GroundTruthPosesReprojectDepthAcrossFrames) {
  GeneratorOptions options = SmallOffice(5);
  options.scene.persons = 1;
  options.scene.frames = 16;
  options.scene.width = 160, options.scene.height = 120;
  options.scene.motion = MotionKind::kXyz;
  const fs::path dir = root_ / "office";
  GenerateSequence(options, dir);
  const auto sequence = OpenSequence("tum:" + dir.string());
  const Trajectory groundtruth = ReadTumTrajectory(dir / "groundtruth.txt");
  const Camera& camera = sequence->GetCamera();
  const FrameData first = sequence->Load(0), last = sequence->Load(15);
  const cv::Mat mask0 = cv::imread((dir / "masks" / "0.000000.png").string(), cv::IMREAD_UNCHANGED);
  const cv::Mat mask1 = cv::imread((dir / "masks" / "0.500000.png").string(), cv::IMREAD_UNCHANGED);
  const Rigid3d last_from_first =
      groundtruth[15].world_from_cam.inverse() * groundtruth[0].world_from_cam;
  EXPECT_GT(last_from_first.translation().norm(), 0.05) << "the camera moved";
  std::vector<double> errors;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const float z = first.depth.at<float>(v, u);
      if (z <= 0.f || mask0.at<uint8_t>(v, u)) continue;
      const Eigen::Vector3d p = last_from_first * camera.Unproject({u, v}, z);
      const Eigen::Vector2d px = camera.ProjectUndistorted(p);
      const int u0 = static_cast<int>(std::floor(px.x())),
                v0 = static_cast<int>(std::floor(px.y()));
      if (u0 < 0 || v0 < 0 || u0 + 1 >= camera.width || v0 + 1 >= camera.height) continue;
      // Inverse depth is affine in pixel coordinates on a plane: interpolate it bilinearly
      // inside planar patches (the four neighbours agree within 2 %), skipping depth edges and
      // pixels of walking persons.
      double inverse[2][2], lo = 1e9, hi = 0;
      bool usable = true;
      for (int dv = 0; dv < 2; ++dv)
        for (int du = 0; du < 2; ++du) {
          const float d = last.depth.at<float>(v0 + dv, u0 + du);
          usable &= d > 0.f && !mask1.at<uint8_t>(v0 + dv, u0 + du);
          lo = std::min<double>(lo, d), hi = std::max<double>(hi, d);
          inverse[dv][du] = d > 0.f ? 1.0 / d : 0.0;
        }
      if (!usable || hi > 1.02 * lo) continue;
      const double fu = px.x() - u0, fv = px.y() - v0;
      const double inv = (1 - fv) * ((1 - fu) * inverse[0][0] + fu * inverse[0][1]) +
                         fv * ((1 - fu) * inverse[1][0] + fu * inverse[1][1]);
      errors.push_back(std::abs(1.0 / inv - p.z()));
    }
  }
  ASSERT_GT(errors.size(), 10000u);
  std::sort(errors.begin(), errors.end());
  // The few percent left are occlusion boundaries (points hidden by furniture in the later
  // frame), so the bound is on the 95th percentile.
  EXPECT_LT(errors[errors.size() / 2], 0.0003);
  EXPECT_LT(errors[errors.size() * 95 / 100], 0.001);
}

// Masks are exactly the pixels of moving objects; every ground-truth box is the tight bound of
// its object's visible pixels; every mask pixel lies in a box of a moving object; the static
// mannequin has boxes but is never in the mask.
TEST_F(GeneratorTest, MasksAndBoxesCoverObjectsExactly) {
  const GeneratorOptions options = SmallOffice(8);
  const fs::path dir = root_ / "office";
  GenerateSequence(options, dir);
  const Scene scene = BuildScene(options.scene);
  const auto detections = ReadDetectionsJsonl(dir / "detections.jsonl");
  ASSERT_EQ(detections.size(), 4u);

  const nlohmann::json description = nlohmann::json::parse(ReadTextFile(dir / "scene.json"));
  ASSERT_EQ(description["objects"].size(), scene.objects.size());
  int moving = 0, still_persons = 0;
  for (const auto& object : description["objects"]) {
    moving += object["moving"].get<bool>();
    still_persons += !object["moving"].get<bool>() && object["class_id"] == 0;
  }
  EXPECT_EQ(moving, 3);
  EXPECT_EQ(still_persons, 1);

  size_t mannequin_boxes = 0, mask_pixels = 0;
  for (size_t i = 0; i < detections.size(); ++i) {
    const std::string stamp = FrameStamp(scene, i);
    EXPECT_EQ(detections[i].name, stamp);
    const RenderedFrame rendered = RenderSceneFrame(scene, i, options);
    const cv::Mat mask =
        cv::imread((dir / "masks" / (stamp + ".png")).string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(mask.type(), CV_8UC1);
    std::map<int, cv::Rect> bounds;
    std::map<int, int> pixels;
    for (int v = 0; v < mask.rows; ++v) {
      for (int u = 0; u < mask.cols; ++u) {
        const int id = rendered.object_id.at<int32_t>(v, u);
        const bool is_moving = id >= 1 && scene.objects[id - 1].moving;
        ASSERT_EQ(mask.at<uint8_t>(v, u), is_moving ? 255 : 0) << u << "," << v;
        if (id < 1) continue;
        cv::Rect& r = bounds[id];
        r = pixels[id]++ ? (r | cv::Rect(u, v, 1, 1)) : cv::Rect(u, v, 1, 1);
      }
    }
    mask_pixels += cv::countNonZero(mask);
    // Expected boxes: every object of a dynamic class with >= min_box_pixels pixels, id order.
    std::vector<cv::Rect> expected;
    for (const auto& [id, rect] : bounds) {
      if (pixels[id] >= options.min_box_pixels) expected.push_back(rect);
      if (!scene.objects[id - 1].moving && pixels[id] >= options.min_box_pixels) ++mannequin_boxes;
    }
    ASSERT_EQ(detections[i].detections.size(), expected.size());
    for (size_t k = 0; k < expected.size(); ++k) {
      const Detection& d = detections[i].detections[k];
      EXPECT_EQ(d.class_id, 0);
      EXPECT_EQ(d.class_name, "person");
      EXPECT_EQ(d.score, 1.f);
      EXPECT_EQ(cv::Rect(d.box), expected[k]);
    }
    // Every mask pixel is inside a box.
    for (int v = 0; v < mask.rows; ++v)
      for (int u = 0; u < mask.cols; ++u) {
        if (!mask.at<uint8_t>(v, u)) continue;
        bool inside = false;
        for (const Detection& d : detections[i].detections)
          inside |= cv::Rect(d.box).contains(cv::Point(u, v));
        ASSERT_TRUE(inside) << u << "," << v;
      }
  }
  EXPECT_GT(mask_pixels, 1000u) << "persons walk through the view";
  EXPECT_GT(mannequin_boxes, 0u) << "the mannequin is visible";
}

TEST_F(GeneratorTest, SameSeedSameBytesOtherSeedDiffers) {
  GeneratorOptions options = SmallOffice(21);
  options.scene.frames = 2;
  options.scene.width = 128, options.scene.height = 96;
  options.noise_sigma = 2.0;
  options.blur_px = 3.0;
  GenerateSequence(options, root_ / "a");
  GenerateSequence(options, root_ / "b");
  options.scene.seed = 22;
  GenerateSequence(options, root_ / "c");
  const auto a = AllFiles(root_ / "a"), b = AllFiles(root_ / "b"), c = AllFiles(root_ / "c");
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.size(), 12u);  // 2 frames x (rgb, depth, mask) + 6 text files
  for (const auto& [name, bytes] : a) {
    ASSERT_TRUE(b.count(name)) << name;
    EXPECT_TRUE(b.at(name) == bytes) << name;
  }
  EXPECT_FALSE(a.at("rgb/0.000000.png") == c.at("rgb/0.000000.png"));
}

TEST_F(GeneratorTest, StreetHasFarDepthCarsAndCyclists) {
  GeneratorOptions options;
  options.scene.scene = "street";
  options.scene.frames = 2;
  options.scene.seed = 4;
  options.scene.width = 414, options.scene.height = 126;  // a third of KITTI
  const fs::path dir = root_ / "street";
  GenerateSequence(options, dir);
  const auto sequence = OpenSequence("tum:" + dir.string());
  ASSERT_EQ(sequence->Size(), 2u);
  EXPECT_NEAR(sequence->GetCamera().fx, 718.856 * 414 / 1241, 1e-9);
  EXPECT_NEAR(sequence->Timestamp(1), 0.1, 1e-9);

  const cv::Mat full =
      cv::imread((dir / "depth_full" / "0.000000.tiff").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(full.type(), CV_32FC1);
  double max_depth = 0;
  cv::minMaxLoc(full, nullptr, &max_depth);
  EXPECT_GT(max_depth, 80.0);
  // The PNG keeps only what fits 16 bits at 1/5000 m.
  const FrameData frame = sequence->Load(0);
  for (int v = 0; v < full.rows; v += 7)
    for (int u = 0; u < full.cols; u += 7) {
      const float z = full.at<float>(v, u);
      if (z > 0 && z < 13.0f) {
        ASSERT_NEAR(frame.depth.at<float>(v, u), z, 0.5 / kDepthPngScale + 1e-6);
      } else {
        ASSERT_EQ(frame.depth.at<float>(v, u), 0.f);
      }
    }
  const nlohmann::json description = nlohmann::json::parse(ReadTextFile(dir / "scene.json"));
  std::map<std::pair<int, bool>, int> counts;
  for (const auto& object : description["objects"])
    ++counts[{object["class_id"].get<int>(), object["moving"].get<bool>()}];
  EXPECT_GT((counts[{2, false}]), 5) << "parked cars";
  EXPECT_GE((counts[{2, true}]), 3) << "moving cars";
  EXPECT_EQ((counts[{1, true}]), 2) << "cyclists";
  const auto detections = ReadDetectionsJsonl(dir / "detections.jsonl");
  std::set<int> classes;
  for (const auto& f : detections)
    for (const auto& d : f.detections) classes.insert(d.class_id);
  EXPECT_TRUE(classes.count(2));
}

TEST_F(GeneratorTest, BadOptionsAndNonEmptyOutputFailCleanly) {
  GeneratorOptions options = SmallOffice(1);
  options.scene.frames = 0;
  EXPECT_THROW(GenerateSequence(options, root_ / "x"), InputError);
  options = SmallOffice(1);
  options.scene.scene = "moon";
  EXPECT_THROW(GenerateSequence(options, root_ / "x"), InputError);
  options = SmallOffice(1);
  options.noise_sigma = -1;
  EXPECT_THROW(GenerateSequence(options, root_ / "x"), InputError);
  EXPECT_FALSE(fs::exists(root_ / "x"));

  fs::create_directories(root_ / "full");
  std::ofstream(root_ / "full" / "keep.txt") << "x";
  options = SmallOffice(1);
  options.scene.frames = 1;
  try {
    GenerateSequence(options, root_ / "full");
    FAIL() << "wrote into a non-empty folder";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("exists and is not empty"), std::string::npos);
  }
  // Nothing but the kept file and no temporary folders are left behind.
  size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(root_)) {
    EXPECT_EQ(entry.path().filename().string().rfind(".tmp", 0), std::string::npos);
    ++entries;
  }
  EXPECT_EQ(entries, 1u);
  // An existing empty folder is fine.
  fs::create_directories(root_ / "empty");
  GenerateSequence(options, root_ / "empty");
  EXPECT_TRUE(fs::exists(root_ / "empty" / "rgb.txt"));
}

}  // namespace
}  // namespace ademono::synth
