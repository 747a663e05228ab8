#include "ademono/synth/generator.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/io/trajectory.h"
#include "ademono/synth/random.h"

namespace fs = std::filesystem;

namespace ademono::synth {

namespace {

// Mean image motion (pixels) over the exposure, from the rendered depth: sparse pixels are
// moved from the pose at t to the pose half a frame earlier.
cv::Point2d MeanImageMotion(const Scene& scene, const cv::Mat& depth, double t) {
  const Camera& camera = scene.camera;
  const Rigid3d world_from_cam = scene.world_from_cam(t);
  const Rigid3d earlier_from_world = scene.world_from_cam(t - 0.5 / scene.fps).inverse();
  cv::Point2d sum(0, 0);
  int count = 0;
  for (int gv = 1; gv < 8; ++gv) {
    for (int gu = 1; gu < 8; ++gu) {
      const int u = gu * camera.width / 8, v = gv * camera.height / 8;
      const float z = depth.at<float>(v, u);
      if (z <= 0.f) continue;
      const Eigen::Vector3d p = earlier_from_world * (world_from_cam * camera.Unproject({u, v}, z));
      if (p.z() <= 1e-3) continue;
      const Eigen::Vector2d px = camera.ProjectUndistorted(p);
      sum += cv::Point2d(px.x() - u, px.y() - v);
      ++count;
    }
  }
  return count ? sum / count : cv::Point2d(0, 0);
}

void ApplyMotionBlur(cv::Mat& image, const cv::Point2d& motion, double length_px) {
  const double norm = std::hypot(motion.x, motion.y);
  if (length_px < 1.0 || norm < 1e-9) return;
  const int radius = static_cast<int>(std::ceil(length_px / 2));
  cv::Mat kernel = cv::Mat::zeros(2 * radius + 1, 2 * radius + 1, CV_32F);
  const cv::Point2d half = motion / norm * (length_px / 2);
  // Sub-pixel line via many samples, so any direction and length gives a smooth kernel.
  const int samples = 8 * static_cast<int>(std::ceil(length_px)) + 1;
  for (int i = 0; i < samples; ++i) {
    const double f = samples == 1 ? 0.0 : -1.0 + 2.0 * i / (samples - 1);
    const double x = radius + f * half.x, y = radius + f * half.y;
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const double ax = x - x0, ay = y - y0;
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const int xx = std::min(x0 + dx, 2 * radius), yy = std::min(y0 + dy, 2 * radius);
        kernel.at<float>(yy, xx) += static_cast<float>((dx ? ax : 1 - ax) * (dy ? ay : 1 - ay));
      }
  }
  kernel /= cv::sum(kernel)[0];
  cv::filter2D(image, image, -1, kernel, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
}

void AddNoise(cv::Mat& image, double sigma, uint64_t seed) {
  if (sigma <= 0) return;
  cv::RNG rng(seed | 1);
  cv::Mat noise(image.size(), CV_32FC3);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  cv::Mat sum;
  image.convertTo(sum, CV_32FC3);
  sum += noise;
  sum.convertTo(image, CV_8UC3);  // rounds and saturates
}

void WriteImageOrThrow(const fs::path& path, const cv::Mat& image) {
  bool ok = false;
  try {
    ok = cv::imwrite(path.string(), image);
  } catch (const cv::Exception& e) {
    ThrowInputError(path, std::string("cannot write image: ") + e.err);
  }
  if (!ok) ThrowInputError(path, "cannot write image");
}

// Removes the temporary output folder unless the run completed.
class TempDirGuard {
 public:
  explicit TempDirGuard(fs::path path) : path_(std::move(path)) {}
  ~TempDirGuard() {
    if (!committed_) {
      std::error_code ec;
      fs::remove_all(path_, ec);
    }
  }
  void Commit() { committed_ = true; }

 private:
  fs::path path_;
  bool committed_ = false;
};

nlohmann::ordered_json SceneJson(const Scene& scene, const GeneratorOptions& options,
                                 MotionKind motion) {
  nlohmann::ordered_json j;
  j["generator"] = "ademono synth";
  j["scene"] = scene.name;
  j["motion"] = MotionKindName(motion);
  j["seed"] = options.scene.seed;
  j["frames"] = options.scene.frames;
  j["fps"] = scene.fps;
  j["noise_sigma"] = options.noise_sigma;
  j["blur_px"] = options.blur_px;
  // Only with photos, so sequences without them keep their bytes.
  if (!options.scene.actor_photos.empty()) j["actor_photos"] = options.scene.actor_photos;
  j["camera"] = {{"width", scene.camera.width}, {"height", scene.camera.height},
                 {"fx", scene.camera.fx},       {"fy", scene.camera.fy},
                 {"cx", scene.camera.cx},       {"cy", scene.camera.cy}};
  j["depth_png_scale"] = kDepthPngScale;
  j["depth_png_max_m"] = 65535.0 / kDepthPngScale;
  j["world_frame"] = "z up; groundtruth.txt poses are world_from_cam";
  nlohmann::ordered_json objects = nlohmann::ordered_json::array();
  for (const SceneObject& object : scene.objects) {
    nlohmann::ordered_json o = {{"id", object.id},
                                {"name", object.name},
                                {"class_id", object.class_id},
                                {"class", object.class_name},
                                {"moving", object.moving}};
    if (!object.appearance.empty()) o["appearance"] = "photo " + object.appearance;
    objects.push_back(o);
  }
  j["objects"] = objects;
  j["static_boxes"] = scene.static_boxes.size();
  return j;
}

}  // namespace

void GeneratorOptions::Check() const {
  scene.Check();
  if (!(noise_sigma >= 0.0) || noise_sigma > 100.0)
    throw std::invalid_argument("noise must be in [0, 100] grey levels");
  if (!(blur_px >= 0.0) || blur_px > 100.0)
    throw std::invalid_argument("blur must be in [0, 100] pixels");
  if (min_box_pixels < 1) throw std::invalid_argument("min_box_pixels must be >= 1");
}

std::string FrameStamp(const Scene& scene, size_t index) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.6f", static_cast<double>(index) / scene.fps);
  return buffer;
}

RenderedFrame RenderSceneFrame(const Scene& scene, size_t index, const GeneratorOptions& options) {
  // Rendered at the written timestamp so images, poses and file names agree exactly.
  const double t = std::stod(FrameStamp(scene, index));
  const std::vector<Box> boxes = scene.BoxesAt(t);
  RenderedFrame frame =
      RenderBoxes(scene.camera, scene.textures, boxes, scene.world_from_cam(t), scene.sky_bgr,
                  scene.sprites);
  if (options.blur_px > 0)
    ApplyMotionBlur(frame.image, MeanImageMotion(scene, frame.depth, t), options.blur_px);
  AddNoise(frame.image, options.noise_sigma, SubSeed(options.scene.seed, 0x401CE + index));
  return frame;
}

std::vector<ObjectExtent> ObjectExtents(const Scene& scene, const cv::Mat& object_id) {
  std::vector<ObjectExtent> extents(scene.objects.size());
  for (int v = 0; v < object_id.rows; ++v) {
    const int32_t* row = object_id.ptr<int32_t>(v);
    for (int u = 0; u < object_id.cols; ++u) {
      const int id = row[u];
      if (id < 1 || id > static_cast<int>(extents.size())) continue;
      ObjectExtent& e = extents[id - 1];
      e.umin = std::min(e.umin, u), e.umax = std::max(e.umax, u);
      e.vmin = std::min(e.vmin, v), e.vmax = std::max(e.vmax, v);
      ++e.pixels;
    }
  }
  return extents;
}

std::string ObjectsJsonLine(const Scene& scene, size_t index, const cv::Mat& object_id) {
  const std::vector<ObjectExtent> extents = ObjectExtents(scene, object_id);
  nlohmann::ordered_json line;
  line["frame"] = index;
  line["name"] = FrameStamp(scene, index);
  nlohmann::ordered_json objects = nlohmann::ordered_json::array();
  for (size_t i = 0; i < extents.size(); ++i) {
    const ObjectExtent& e = extents[i];
    if (e.pixels == 0) continue;
    objects.push_back({{"id", scene.objects[i].id},
                       {"box_xywh", {e.umin, e.vmin, e.umax - e.umin + 1, e.vmax - e.vmin + 1}},
                       {"pixels", e.pixels}});
  }
  line["objects"] = objects;
  return line.dump() + "\n";
}

std::vector<Detection> BoxesFromObjectIds(const Scene& scene, const cv::Mat& object_id,
                                          int min_box_pixels) {
  const std::vector<ObjectExtent> extents = ObjectExtents(scene, object_id);
  const std::vector<int>& dynamic = DefaultDynamicClassIds();
  std::vector<Detection> detections;
  for (size_t i = 0; i < extents.size(); ++i) {
    const SceneObject& object = scene.objects[i];
    const ObjectExtent& e = extents[i];
    if (e.pixels < min_box_pixels) continue;
    if (std::find(dynamic.begin(), dynamic.end(), object.class_id) == dynamic.end()) continue;
    Detection d;
    d.class_id = object.class_id;
    d.class_name = object.class_name;
    d.score = 1.f;
    // Pixel-area extent: the box covers pixels umin..umax inclusive.
    d.box = cv::Rect2f(static_cast<float>(e.umin), static_cast<float>(e.vmin),
                       static_cast<float>(e.umax - e.umin + 1),
                       static_cast<float>(e.vmax - e.vmin + 1));
    detections.push_back(d);
  }
  return detections;
}

cv::Mat MovingMask(const Scene& scene, const cv::Mat& object_id) {
  std::vector<uint8_t> moving(scene.objects.size() + 1, 0);
  for (const SceneObject& object : scene.objects) moving[object.id] = object.moving ? 255 : 0;
  cv::Mat mask(object_id.size(), CV_8UC1);
  for (int v = 0; v < object_id.rows; ++v) {
    const int32_t* ids = object_id.ptr<int32_t>(v);
    uint8_t* out = mask.ptr<uint8_t>(v);
    for (int u = 0; u < object_id.cols; ++u) {
      const int id = ids[u];
      out[u] = (id >= 1 && id < static_cast<int>(moving.size())) ? moving[id] : 0;
    }
  }
  return mask;
}

cv::Mat DepthToPng(const cv::Mat& depth_m) {
  cv::Mat png(depth_m.size(), CV_16UC1);
  for (int v = 0; v < depth_m.rows; ++v) {
    const float* in = depth_m.ptr<float>(v);
    uint16_t* out = png.ptr<uint16_t>(v);
    for (int u = 0; u < depth_m.cols; ++u) {
      const double units = std::round(static_cast<double>(in[u]) * kDepthPngScale);
      out[u] = (in[u] > 0.f && units <= 65535.0) ? static_cast<uint16_t>(units) : 0;
    }
  }
  return png;
}

namespace {

GeneratorSummary GenerateSequenceInto(const GeneratorOptions& options, const fs::path& out_dir,
                                      const std::function<void(size_t, size_t)>& progress) {
  try {
    options.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("invalid options: ") + e.what());
  }
  fs::path out = fs::absolute(out_dir).lexically_normal();
  if (out.filename().empty()) out = out.parent_path();
  std::error_code ec;
  if (fs::exists(out, ec)) {
    if (!fs::is_directory(out, ec)) ThrowInputError(out, "exists and is not a folder");
    if (!fs::is_empty(out, ec)) ThrowInputError(out, "exists and is not empty");
  }
  fs::create_directories(out.parent_path(), ec);
  if (ec) ThrowInputError(out.parent_path(), "cannot create folder: " + ec.message());

  const auto start = std::chrono::steady_clock::now();
  const Scene scene = BuildScene(options.scene);
  const MotionKind motion = options.scene.motion.value_or(
      scene.name == "street" ? MotionKind::kForward : MotionKind::kXyz);

  const fs::path tmp = out.parent_path() /
                       (".tmp.synth." + std::to_string(::getpid()) + "." + out.filename().string());
  fs::remove_all(tmp, ec);
  TempDirGuard guard(tmp);
  const bool full_depth = scene.name == "street";
  for (const char* sub : {"rgb", "depth", "masks"}) fs::create_directories(tmp / sub);
  if (full_depth) fs::create_directories(tmp / "depth_full");

  GeneratorSummary summary;
  std::string rgb_list =
      "# color images\n# file: 'ademono synth " + scene.name + "'\n# timestamp filename\n";
  std::string depth_list =
      "# depth maps\n# file: 'ademono synth " + scene.name + "'\n# timestamp filename\n";
  Trajectory groundtruth;
  std::vector<FrameDetections> detections;
  const bool object_truth = !options.scene.actor_photos.empty();
  std::string objects_jsonl;
  double moving_fraction_sum = 0.0;
  for (size_t i = 0; i < options.scene.frames; ++i) {
    const auto render_start = std::chrono::steady_clock::now();
    const RenderedFrame frame = RenderSceneFrame(scene, i, options);
    const cv::Mat mask = MovingMask(scene, frame.object_id);
    FrameDetections frame_detections;
    frame_detections.frame = i;
    const std::string stamp = FrameStamp(scene, i);
    frame_detections.timestamp = std::stod(stamp);
    frame_detections.name = stamp;
    frame_detections.detections =
        BoxesFromObjectIds(scene, frame.object_id, options.min_box_pixels);
    if (object_truth) objects_jsonl += ObjectsJsonLine(scene, i, frame.object_id);
    summary.seconds_rendering +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - render_start).count();
    summary.detections += frame_detections.detections.size();
    moving_fraction_sum += cv::countNonZero(mask) / static_cast<double>(mask.total());

    WriteImageOrThrow(tmp / "rgb" / (stamp + ".png"), frame.image);
    WriteImageOrThrow(tmp / "depth" / (stamp + ".png"), DepthToPng(frame.depth));
    WriteImageOrThrow(tmp / "masks" / (stamp + ".png"), mask);
    if (full_depth) WriteImageOrThrow(tmp / "depth_full" / (stamp + ".tiff"), frame.depth);
    rgb_list += stamp + " rgb/" + stamp + ".png\n";
    depth_list += stamp + " depth/" + stamp + ".png\n";
    groundtruth.push_back(
        {frame_detections.timestamp, scene.world_from_cam(frame_detections.timestamp)});
    detections.push_back(std::move(frame_detections));
    if (progress) progress(i + 1, options.scene.frames);
  }
  WriteTextFileAtomic(tmp / "rgb.txt", rgb_list);
  WriteTextFileAtomic(tmp / "depth.txt", depth_list);
  WriteTumTrajectory(tmp / "groundtruth.txt", groundtruth);
  WriteCameraYaml(tmp / "camera.yaml", scene.camera);
  WriteDetectionsJsonl(tmp / "detections.jsonl", detections);
  if (object_truth) WriteTextFileAtomic(tmp / "objects.jsonl", objects_jsonl);
  WriteTextFileAtomic(tmp / "scene.json", SceneJson(scene, options, motion).dump(1) + "\n");

  if (fs::exists(out, ec)) fs::remove(out, ec);  // an empty folder (checked above)
  fs::rename(tmp, out, ec);
  if (ec) ThrowInputError(out, "cannot move the finished sequence into place: " + ec.message());
  guard.Commit();
  summary.frames = options.scene.frames;
  summary.moving_pixel_fraction = moving_fraction_sum / std::max<size_t>(1, summary.frames);
  summary.seconds_total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace

GeneratorSummary GenerateSequence(const GeneratorOptions& options, const fs::path& out_dir,
                                  const std::function<void(size_t, size_t)>& progress) {
  try {
    return GenerateSequenceInto(options, out_dir, progress);
  } catch (const fs::filesystem_error& e) {
    // Disk full, permissions...: one line naming the path (the temporary folder is gone).
    ThrowInputError(e.path1().empty() ? out_dir : e.path1(), e.code().message());
  }
}

}  // namespace ademono::synth
