// Microsoft 7-Scenes: frame-XXXXXX.color.{png,jpg}, frame-XXXXXX.depth.png (uint16 mm, 0 and
// 65535 = no depth), frame-XXXXXX.pose.txt (4x4 world_from_cam), 30 Hz.
#include <algorithm>
#include <charconv>
#include <map>
#include <optional>
#include <string_view>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/io/file_sequence.h"

namespace fs = std::filesystem;

namespace ademono {

namespace {

constexpr double kSevenScenesFps = 30.0;

// The intrinsics the 7-Scenes authors publish; used when the folder has no intrinsics file.
Camera DefaultSevenScenesCamera() {
  Camera camera;
  camera.fx = camera.fy = 585.0;
  camera.cx = 320.0;
  camera.cy = 240.0;
  return camera;
}

Rigid3d ReadMatrix4x4(const fs::path& path) {
  Eigen::Matrix4d m;
  size_t rows = 0;
  ForEachDataLine(path, false, [&](size_t line, const std::vector<std::string_view>& f) {
    if (rows >= 4) ThrowInputError(path, line, "expected 4 rows of a 4x4 matrix, found more");
    if (f.size() != 4) {
      ThrowInputError(path, line, "expected 4 fields, found " + std::to_string(f.size()));
    }
    for (size_t c = 0; c < 4; ++c) m(rows, c) = ParseDouble(f[c], path, line, c);
    ++rows;
  });
  if (rows != 4)
    ThrowInputError(path, "expected a 4x4 matrix, found " + std::to_string(rows) + " rows");
  if (std::abs(m.topLeftCorner<3, 3>().determinant()) < 1e-6) {
    ThrowInputError(path, "rotation part is singular");
  }
  return MakeRigid3d(m);
}

Camera ReadIntrinsics(const fs::path& path) {
  Eigen::Matrix3d k;
  size_t rows = 0;
  ForEachDataLine(path, false, [&](size_t line, const std::vector<std::string_view>& f) {
    if (rows >= 3) ThrowInputError(path, line, "expected a 3x3 matrix, found more rows");
    if (f.size() != 3) {
      ThrowInputError(path, line, "expected 3 fields, found " + std::to_string(f.size()));
    }
    for (size_t c = 0; c < 3; ++c) k(rows, c) = ParseDouble(f[c], path, line, c);
    ++rows;
  });
  if (rows != 3)
    ThrowInputError(path, "expected a 3x3 matrix, found " + std::to_string(rows) + " rows");
  Camera camera;
  camera.fx = k(0, 0);
  camera.fy = k(1, 1);
  camera.cx = k(0, 2);
  camera.cy = k(1, 2);
  return camera;
}

// "frame-000123.color.jpg" / ".png" -> 123; nullopt for any other name.
std::optional<long> ColourFrameNumber(const std::string& name) {
  static constexpr std::string_view kPrefix = "frame-";
  if (name.rfind(kPrefix, 0) != 0) return std::nullopt;
  const size_t digits_end = name.find('.', kPrefix.size());
  if (digits_end == std::string::npos || digits_end == kPrefix.size()) return std::nullopt;
  const std::string rest = name.substr(digits_end);
  if (rest != ".color.jpg" && rest != ".color.png") return std::nullopt;
  long number = 0;
  const char* begin = name.data() + kPrefix.size();
  const char* end = name.data() + digits_end;
  const auto [ptr, ec] = std::from_chars(begin, end, number);
  if (ec != std::errc() || ptr != end) return std::nullopt;
  return number;
}

}  // namespace

std::unique_ptr<Sequence> OpenSevenScenes(const fs::path& dir,
                                          const std::optional<fs::path>& camera_yaml) {
  RequireDirectory(dir);
  std::map<long, fs::path> images;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const auto number = ColourFrameNumber(entry.path().filename().string());
    if (!number) continue;
    if (!images.emplace(*number, entry.path()).second) {
      ThrowInputError(entry.path(),
                      "frame " + std::to_string(*number) + " has more than one colour image");
    }
  }

  FileSequenceSpec spec;
  spec.kind = "7scenes";
  spec.path = dir;
  spec.depth_scale = 0.001;
  size_t with_depth = 0, with_pose = 0;
  for (const auto& [number, image] : images) {
    FileFrame frame;
    frame.timestamp = static_cast<double>(number) / kSevenScenesFps;
    frame.image = image;
    // "frame-000000.color.jpg" -> "frame-000000"
    const std::string stem =
        image.filename().string().substr(0, image.filename().string().find('.'));
    const fs::path depth = dir / (stem + ".depth.png");
    const fs::path pose = dir / (stem + ".pose.txt");
    if (fs::exists(depth)) {
      frame.depth = depth;
      ++with_depth;
    }
    if (fs::exists(pose)) {
      frame.world_from_cam_gt = ReadMatrix4x4(pose);
      ++with_pose;
    }
    spec.frames.push_back(std::move(frame));
  }
  if (spec.frames.empty()) ThrowInputError(dir, "sequence has no frames");
  spec.has_depth = with_depth == spec.frames.size();
  spec.has_ground_truth = with_pose == spec.frames.size();

  if (camera_yaml) {
    spec.camera = LoadCameraYaml(*camera_yaml);
  } else {
    const fs::path intrinsics = dir / "camera-intrinsics.txt";
    spec.camera = fs::exists(intrinsics) ? ReadIntrinsics(intrinsics) : DefaultSevenScenesCamera();
    const cv::Size size = ImageSizeOf(spec.frames.front().image);
    spec.camera.width = size.width;
    spec.camera.height = size.height;
    try {
      spec.camera.Check();
    } catch (const std::invalid_argument& e) {
      ThrowInputError(intrinsics, e.what());
    }
  }
  return std::make_unique<FileSequence>(std::move(spec));
}

}  // namespace ademono
