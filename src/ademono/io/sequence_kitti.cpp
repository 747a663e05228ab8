// KITTI odometry: DIR/image_0 (grey left) or DIR/image_2 (colour left), calib.txt with P0/P2
// (3x4 projection: fx, cx, fy, cy), times.txt (seconds per frame), ground truth poses/NN.txt
// (NN = DIR's name) in DIR, DIR/.., or DIR/../.. (the official dataset/poses/ layout).
// The KITTI rig's camera height above the road (1.65 m) comes with the calibration
// (Sequence::CameraHeight), not with a --camera YAML (another rig).
#include <algorithm>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/io/file_sequence.h"
#include "ademono/io/trajectory.h"

namespace fs = std::filesystem;

namespace ademono {

namespace {

constexpr double kKittiFps = 10.0;
// The cameras' height above the road on the KITTI recording car (Geiger et al., IJRR 2013).
constexpr double kKittiCameraHeight = 1.65;

// The camera of line `key` and, in `cam_from_cam0`, its offset from camera 0 (whose poses
// poses/NN.txt gives): the rectified projection is P = K [I | t], so t = K^-1 P(:, 3).
Camera ReadKittiCalib(const fs::path& calib, const std::string& key,
                      Eigen::Vector3d* cam_from_cam0) {
  std::optional<Camera> camera;
  ForEachDataLine(calib, false, [&](size_t line, const std::vector<std::string_view>& f) {
    if (f.front() != key + ":") return;
    if (f.size() != 13) {
      ThrowInputError(calib, line,
                      key + " needs 12 numbers, found " + std::to_string(f.size() - 1));
    }
    double p[12];
    for (size_t i = 0; i < 12; ++i) p[i] = ParseDouble(f[i + 1], calib, line, i + 1);
    Camera c;
    c.fx = p[0];
    c.cx = p[2];
    c.fy = p[5];
    c.cy = p[6];
    camera = c;
    const double tz = p[11];
    const double ty = (p[7] - c.cy * tz) / c.fy;
    const double tx = (p[3] - c.cx * tz - p[1] * ty) / c.fx;
    *cam_from_cam0 = Eigen::Vector3d(tx, ty, tz);
  });
  if (!camera) ThrowInputError(calib, "has no " + key + " line");
  return *camera;
}

std::optional<fs::path> FindKittiPoses(const fs::path& dir) {
  const fs::path abs = fs::absolute(dir).lexically_normal();
  const std::string number = (abs.has_filename() ? abs : abs.parent_path()).filename().string();
  const fs::path base = abs.has_filename() ? abs : abs.parent_path();
  for (const fs::path& candidate :
       {base / "poses" / (number + ".txt"), base.parent_path() / "poses" / (number + ".txt"),
        base.parent_path().parent_path() / "poses" / (number + ".txt")}) {
    if (fs::is_regular_file(candidate)) return candidate;
  }
  return std::nullopt;
}

}  // namespace

std::unique_ptr<Sequence> OpenKitti(const fs::path& dir,
                                    const std::optional<fs::path>& camera_yaml) {
  RequireDirectory(dir);
  const bool grey = fs::is_directory(dir / "image_0");
  const fs::path image_dir = dir / (grey ? "image_0" : "image_2");
  if (!fs::is_directory(image_dir)) ThrowInputError(dir, "has neither image_0/ nor image_2/");
  std::vector<fs::path> images;
  for (const auto& entry : fs::directory_iterator(image_dir)) {
    if (entry.is_regular_file() && IsImageFile(entry.path())) images.push_back(entry.path());
  }
  std::sort(images.begin(), images.end());
  if (images.empty()) ThrowInputError(dir, "sequence has no frames");

  FileSequenceSpec spec;
  spec.kind = "kitti";
  spec.path = dir;

  std::vector<double> times;
  const fs::path times_file = dir / "times.txt";
  if (fs::exists(times_file)) {
    ForEachDataLine(times_file, false, [&](size_t line, const std::vector<std::string_view>& f) {
      if (f.size() != 1) {
        ThrowInputError(times_file, line, "expected 1 field, found " + std::to_string(f.size()));
      }
      times.push_back(ParseDouble(f[0], times_file, line, 0));
    });
    if (times.size() != images.size()) {
      ThrowInputError(times_file, "has " + std::to_string(times.size()) + " times for " +
                                      std::to_string(images.size()) + " images");
    }
  } else {
    for (size_t i = 0; i < images.size(); ++i) times.push_back(static_cast<double>(i) / kKittiFps);
  }

  Trajectory poses;
  if (const auto poses_file = FindKittiPoses(dir)) {
    poses = ReadKittiTrajectory(*poses_file);
    if (poses.size() != images.size()) {
      ThrowInputError(*poses_file, "has " + std::to_string(poses.size()) + " poses for " +
                                       std::to_string(images.size()) + " images");
    }
    spec.has_ground_truth = true;
  }
  // The ground truth is camera 0's (the left grey camera); the colour camera sits 6 cm to its
  // left: its poses are camera 0's moved by the calibration's offset.
  Rigid3d cam0_from_cam = Rigid3d::Identity();
  if (camera_yaml) {
    spec.camera = LoadCameraYaml(*camera_yaml);
  } else {
    const fs::path calib = dir / "calib.txt";
    Eigen::Vector3d cam_from_cam0 = Eigen::Vector3d::Zero();
    spec.camera = ReadKittiCalib(calib, grey ? "P0" : "P2", &cam_from_cam0);
    cam0_from_cam.translation() = -cam_from_cam0;
    spec.camera_height = kKittiCameraHeight;
    const cv::Size size = ImageSizeOf(images.front());
    spec.camera.width = size.width;
    spec.camera.height = size.height;
    try {
      spec.camera.Check();
    } catch (const std::invalid_argument& e) {
      ThrowInputError(calib, e.what());
    }
  }
  for (size_t i = 0; i < images.size(); ++i) {
    FileFrame frame{times[i], images[i], {}, std::nullopt};
    if (!poses.empty()) frame.world_from_cam_gt = poses[i].world_from_cam * cam0_from_cam;
    spec.frames.push_back(std::move(frame));
  }
  return std::make_unique<FileSequence>(std::move(spec));
}

}  // namespace ademono
