// EuRoC MAV (ASL format): mav0/cam0/data.csv ("timestamp_ns,filename"), mav0/cam0/data/,
// mav0/cam0/sensor.yaml (intrinsics, radial-tangential distortion, T_BS = body_from_cam), ground
// truth mav0/state_groundtruth_estimate0/data.csv (world_from_body), interpolated at image times.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <sstream>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/io/file_sequence.h"
#include "ademono/io/timed_poses.h"

namespace fs = std::filesystem;

namespace ademono {

namespace {

std::vector<double> ReadNumberList(const YAML::Node& node, const fs::path& path,
                                   const std::string& key, size_t min_size) {
  if (!node || !node.IsSequence() || node.size() < min_size) {
    ThrowInputError(path, "field '" + key + "' must be a list of at least " +
                              std::to_string(min_size) + " numbers");
  }
  std::vector<double> values;
  try {
    for (const auto& v : node) values.push_back(v.as<double>());
  } catch (const YAML::Exception&) {
    ThrowInputError(path, "field '" + key + "' holds a non-number");
  }
  return values;
}

struct EurocCamera {
  Camera camera;
  Rigid3d body_from_cam = Rigid3d::Identity();
};

EurocCamera ParseSensorYaml(const YAML::Node& root, const fs::path& path);

EurocCamera ReadSensorYaml(const fs::path& path) {
  // EuRoC files start with OpenCV's "%YAML:1.0", which is not a YAML directive yaml-cpp accepts.
  std::string text = ReadTextFile(path);
  if (text.rfind("%YAML", 0) == 0) text = text.substr(std::min(text.find('\n'), text.size()));
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    ThrowInputError(path, static_cast<size_t>(e.mark.line + 1), "malformed YAML: " + e.msg);
  }
  if (!root.IsMap()) ThrowInputError(path, "sensor.yaml must be a mapping");
  // Fields of the wrong kind (a scalar where a map is expected, a list as distortion_model)
  // throw yaml-cpp exceptions; they are bad input too (found by fuzz_sequence_euroc).
  try {
    return ParseSensorYaml(root, path);
  } catch (const YAML::Exception& e) {
    ThrowInputError(path, "malformed sensor.yaml: " + e.msg);
  }
}

EurocCamera ParseSensorYaml(const YAML::Node& root, const fs::path& path) {
  EurocCamera out;
  const auto intrinsics = ReadNumberList(root["intrinsics"], path, "intrinsics", 4);
  const auto resolution = ReadNumberList(root["resolution"], path, "resolution", 2);
  out.camera.fx = intrinsics[0];
  out.camera.fy = intrinsics[1];
  out.camera.cx = intrinsics[2];
  out.camera.cy = intrinsics[3];
  for (const double side : {resolution[0], resolution[1]}) {
    // Bounded before the int conversion, which is undefined for e.g. 1e300.
    if (!(side >= 1 && side <= 100000)) {
      ThrowInputError(path, "field 'resolution' must hold two sizes from 1 to 100000 pixels");
    }
  }
  out.camera.width = static_cast<int>(resolution[0]);
  out.camera.height = static_cast<int>(resolution[1]);
  if (root["distortion_coefficients"]) {
    if (root["distortion_model"] &&
        root["distortion_model"].as<std::string>() != "radial-tangential") {
      ThrowInputError(path, "distortion_model '" + root["distortion_model"].as<std::string>() +
                                "' is not supported (only radial-tangential)");
    }
    const auto d =
        ReadNumberList(root["distortion_coefficients"], path, "distortion_coefficients", 4);
    for (size_t i = 0; i < std::min<size_t>(d.size(), 5); ++i) out.camera.distortion[i] = d[i];
  }
  try {
    out.camera.Check();
  } catch (const std::invalid_argument& e) {
    ThrowInputError(path, e.what());
  }
  if (root["T_BS"]) {
    const auto data = ReadNumberList(root["T_BS"]["data"], path, "T_BS.data", 16);
    if (data.size() != 16) ThrowInputError(path, "field 'T_BS.data' must hold 16 numbers");
    Eigen::Matrix4d m;
    for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = data[i];
    if (!m.allFinite() || std::abs(m.topLeftCorner<3, 3>().determinant()) < 1e-6) {
      ThrowInputError(path, "field 'T_BS.data': rotation part is singular or not finite");
    }
    out.body_from_cam = MakeRigid3d(m);
  }
  return out;
}

}  // namespace

std::unique_ptr<Sequence> OpenEuroc(const fs::path& dir,
                                    const std::optional<fs::path>& camera_yaml) {
  RequireDirectory(dir);
  const fs::path mav0 = fs::is_directory(dir / "mav0") ? dir / "mav0" : dir;
  const fs::path cam_dir = mav0 / "cam0";
  RequireDirectory(cam_dir);
  const fs::path list = cam_dir / "data.csv";

  FileSequenceSpec spec;
  spec.kind = "euroc";
  spec.path = dir;
  ForEachDataLine(list, true, [&](size_t line, const std::vector<std::string_view>& f) {
    if (f.size() != 2) {
      ThrowInputError(
          list, line,
          "expected 2 fields (timestamp_ns,filename), found " + std::to_string(f.size()));
    }
    const double t = ParseDouble(f[0], list, line, 0) * 1e-9;
    if (!spec.frames.empty() && t <= spec.frames.back().timestamp) {
      ThrowInputError(list, line, "timestamps are not increasing");
    }
    spec.frames.push_back({t, cam_dir / "data" / std::string(f[1]), {}, std::nullopt});
  });
  if (spec.frames.empty()) ThrowInputError(dir, "sequence has no frames");

  const EurocCamera sensor = ReadSensorYaml(cam_dir / "sensor.yaml");
  spec.camera = camera_yaml ? LoadCameraYaml(*camera_yaml) : sensor.camera;

  const fs::path gt_file = mav0 / "state_groundtruth_estimate0" / "data.csv";
  if (fs::exists(gt_file)) {
    const Trajectory world_from_body = ReadEurocTrajectory(gt_file);
    bool any = false;
    for (auto& frame : spec.frames) {
      if (auto pose = LookupPose(world_from_body, frame.timestamp)) {
        frame.world_from_cam_gt = *pose * sensor.body_from_cam;
        any = true;
      }
    }
    spec.has_ground_truth = any;
  }
  return std::make_unique<FileSequence>(std::move(spec));
}

}  // namespace ademono
