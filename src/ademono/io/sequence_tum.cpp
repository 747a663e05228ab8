// TUM RGB-D: rgb.txt / depth.txt ("timestamp filename"), groundtruth.txt (TUM trajectory), depth
// PNG uint16 with 5000 units per metre. Colour and depth are paired like TUM's associate.py
// (nearest timestamps within 0.02 s, greedy by smallest difference, each used once); colour
// frames without a depth partner are dropped when depth.txt exists.
#include <algorithm>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/io/file_sequence.h"
#include "ademono/io/timed_poses.h"

namespace fs = std::filesystem;

namespace ademono {

namespace {

constexpr double kTumDepthUnitsPerMetre = 5000.0;
constexpr double kTumAssociationMaxDiff = 0.02;

struct TimedFile {
  double timestamp;
  fs::path path;
};

std::vector<TimedFile> ReadFileList(const fs::path& list, const fs::path& dir) {
  std::vector<TimedFile> files;
  ForEachDataLine(list, false, [&](size_t line, const std::vector<std::string_view>& f) {
    if (f.size() != 2) {
      ThrowInputError(list, line,
                      "expected 2 fields (timestamp filename), found " + std::to_string(f.size()));
    }
    files.push_back({ParseDouble(f[0], list, line, 0), dir / std::string(f[1])});
  });
  std::stable_sort(files.begin(), files.end(), [](const TimedFile& a, const TimedFile& b) {
    return a.timestamp < b.timestamp;
  });
  return files;
}

// Calibrated intrinsics of the three Kinects, from the TUM RGB-D dataset page.
std::optional<Camera> TumDefaultCamera(const fs::path& dir) {
  const std::string name = fs::absolute(dir).lexically_normal().string();
  Camera camera;
  camera.width = 640;
  camera.height = 480;
  if (name.find("freiburg1") != std::string::npos) {
    camera.fx = 517.3, camera.fy = 516.5, camera.cx = 318.6, camera.cy = 255.3;
    camera.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
  } else if (name.find("freiburg2") != std::string::npos) {
    camera.fx = 520.9, camera.fy = 521.0, camera.cx = 325.1, camera.cy = 249.7;
    camera.distortion = {0.2312, -0.7849, -0.0033, -0.0001, 0.9172};
  } else if (name.find("freiburg3") != std::string::npos) {
    camera.fx = 535.4, camera.fy = 539.2, camera.cx = 320.1, camera.cy = 247.6;
  } else {
    return std::nullopt;
  }
  return camera;
}

}  // namespace

std::unique_ptr<Sequence> OpenTum(const fs::path& dir, const std::optional<fs::path>& camera_yaml) {
  RequireDirectory(dir);
  const std::vector<TimedFile> rgb = ReadFileList(dir / "rgb.txt", dir);
  const fs::path depth_list = dir / "depth.txt";
  const fs::path gt_file = dir / "groundtruth.txt";

  FileSequenceSpec spec;
  spec.kind = "tum";
  spec.path = dir;
  spec.depth_scale = 1.0 / kTumDepthUnitsPerMetre;
  if (fs::exists(depth_list)) {
    const std::vector<TimedFile> depth = ReadFileList(depth_list, dir);
    std::vector<double> rgb_times, depth_times;
    for (const auto& f : rgb) rgb_times.push_back(f.timestamp);
    for (const auto& f : depth) depth_times.push_back(f.timestamp);
    for (const auto& [i, j] : AssociateTimestamps(rgb_times, depth_times, kTumAssociationMaxDiff)) {
      spec.frames.push_back({rgb[i].timestamp, rgb[i].path, depth[j].path, std::nullopt});
    }
    spec.has_depth = true;
  } else {
    for (const auto& f : rgb) spec.frames.push_back({f.timestamp, f.path, {}, std::nullopt});
  }
  if (spec.frames.empty()) ThrowInputError(dir, "sequence has no frames");

  if (fs::exists(gt_file)) {
    Trajectory gt = ReadTumTrajectory(gt_file);
    std::stable_sort(gt.begin(), gt.end(), [](const StampedPose& a, const StampedPose& b) {
      return a.timestamp < b.timestamp;
    });
    bool any = false;
    for (auto& frame : spec.frames) {
      frame.world_from_cam_gt = LookupPose(gt, frame.timestamp);
      any = any || frame.world_from_cam_gt.has_value();
    }
    spec.has_ground_truth = any;
  }

  // An explicit camera wins; then the folder's own camera.yaml; then the Kinect of the folder name.
  std::optional<Camera> fallback;
  if (fs::exists(dir / "camera.yaml")) {
    fallback = LoadCameraYaml(dir / "camera.yaml");
  } else {
    fallback = TumDefaultCamera(dir);
  }
  spec.camera = ResolveCamera(
      camera_yaml, fallback, dir,
      "no camera.yaml in the folder and the name names no freiburg1/2/3 camera; pass a camera "
      "YAML");
  return std::make_unique<FileSequence>(std::move(spec));
}

}  // namespace ademono
