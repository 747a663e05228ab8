#include "ademono/core/camera.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <opencv2/calib3d.hpp>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"

namespace ademono {

bool Camera::HasDistortion() const {
  for (double d : distortion)
    if (d != 0.0) return true;
  return false;
}

void Camera::Check() const {
  if (width <= 0 || height <= 0) throw std::invalid_argument("camera width and height must be > 0");
  if (!(fx > 0) || !(fy > 0) || !std::isfinite(fx) || !std::isfinite(fy))
    throw std::invalid_argument("camera fx and fy must be finite and > 0");
  if (!std::isfinite(cx) || !std::isfinite(cy))
    throw std::invalid_argument("camera cx and cy must be finite");
  // A principal point off the image means the calibration belongs to other images (another
  // resolution or crop); tracking would run, but with every ray wrong.
  if (cx < 0 || cx > width || cy < 0 || cy > height) {
    std::ostringstream message;
    message << "camera principal point (" << cx << ", " << cy << ") is outside the image ("
            << width << "x" << height << ")";
    throw std::invalid_argument(message.str());
  }
  for (double d : distortion)
    if (!std::isfinite(d)) throw std::invalid_argument("camera distortion must be finite");
}

Eigen::Matrix3d Camera::K() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

cv::Mat Camera::KMat() const { return (cv::Mat_<double>(3, 3) << fx, 0, cx, 0, fy, cy, 0, 0, 1); }

cv::Mat Camera::DistortionMat() const {
  return (cv::Mat_<double>(1, 5) << distortion[0], distortion[1], distortion[2], distortion[3],
          distortion[4]);
}

Eigen::Vector2d Camera::ProjectUndistorted(const Eigen::Vector3d& p) const {
  return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
}

Eigen::Vector2d Camera::Distort(const Eigen::Vector2d& px) const {
  if (!HasDistortion()) return px;
  const double x = (px.x() - cx) / fx, y = (px.y() - cy) / fy;
  const auto [k1, k2, p1, p2, k3] = distortion;
  const double r2 = x * x + y * y;
  const double radial = 1 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2;
  const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return {fx * xd + cx, fy * yd + cy};
}

Eigen::Vector2d Camera::Project(const Eigen::Vector3d& p) const {
  return Distort(ProjectUndistorted(p));
}

Eigen::Vector2d Camera::Undistort(const Eigen::Vector2d& px) const {
  if (!HasDistortion()) return px;
  std::vector<cv::Point2f> in{cv::Point2f(static_cast<float>(px.x()), static_cast<float>(px.y()))};
  auto out = Undistort(in);
  return {out[0].x, out[0].y};
}

std::vector<cv::Point2f> Camera::Undistort(const std::vector<cv::Point2f>& px) const {
  if (!HasDistortion() || px.empty()) return px;
  std::vector<cv::Point2f> out;
  // OpenCV's default 5 iterations leave ~0.1 px error at the corners of strongly distorted lenses.
  cv::undistortPoints(
      px, out, KMat(), DistortionMat(), cv::noArray(), KMat(),
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12));
  return out;
}

Eigen::Vector3d Camera::Unproject(const Eigen::Vector2d& px, double depth) const {
  return {(px.x() - cx) / fx * depth, (px.y() - cy) / fy * depth, depth};
}

bool Camera::InImage(const Eigen::Vector2d& px, double border) const {
  return px.x() >= border && px.y() >= border && px.x() <= width - 1 - border &&
         px.y() <= height - 1 - border;
}

Camera Camera::Pinhole(int width, int height, double focal, double cx, double cy) {
  Camera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = focal;
  c.cx = cx;
  c.cy = cy;
  return c;
}

Camera Camera::Scaled(double sx, double sy) const {
  Camera c = *this;
  c.width = static_cast<int>(std::lround(width * sx));
  c.height = static_cast<int>(std::lround(height * sy));
  c.fx *= sx;
  c.fy *= sy;
  // Pixel centres: (u + 0.5) * s - 0.5.
  c.cx = (cx + 0.5) * sx - 0.5;
  c.cy = (cy + 0.5) * sy - 0.5;
  return c;
}

namespace {
constexpr int kMaxCameraSide = 100000;

double RequireNumber(const YAML::Node& node, const char* key, const std::filesystem::path& path) {
  if (!node[key]) ThrowInputError(path, std::string("camera field '") + key + "' is missing");
  try {
    double v = node[key].as<double>();
    if (!std::isfinite(v)) throw YAML::Exception(YAML::Mark::null_mark(), "not finite");
    return v;
  } catch (const YAML::Exception&) {
    ThrowInputError(path, std::string("camera field '") + key + "' is not a number");
  }
}

// Image sizes are whole pixels; the bound keeps the int conversion defined (`width: 1e300`).
int RequireSize(const YAML::Node& node, const char* key, const std::filesystem::path& path) {
  const double v = RequireNumber(node, key, path);
  if (!(v >= 1 && v <= kMaxCameraSide) || v != std::floor(v)) {
    ThrowInputError(path, std::string("camera field '") + key +
                              "' must be a whole number from 1 to " +
                              std::to_string(kMaxCameraSide));
  }
  return static_cast<int>(v);
}
}  // namespace

Camera ParseCameraNode(const YAML::Node& root, const std::filesystem::path& path) {
  // Indexing a scalar or list root throws a yaml-cpp exception, not InputError (found by fuzzing).
  if (!root.IsMap()) ThrowInputError(path, "camera YAML must be a mapping");
  const YAML::Node node = root["camera"] ? root["camera"] : root;
  if (!node.IsMap()) ThrowInputError(path, "camera YAML must be a mapping");
  Camera c;
  c.width = RequireSize(node, "width", path);
  c.height = RequireSize(node, "height", path);
  c.fx = RequireNumber(node, "fx", path);
  c.fy = RequireNumber(node, "fy", path);
  c.cx = RequireNumber(node, "cx", path);
  c.cy = RequireNumber(node, "cy", path);
  if (node["distortion"]) {
    const auto& d = node["distortion"];
    if (!d.IsSequence() || d.size() < 4 || d.size() > 5)
      ThrowInputError(path, "camera field 'distortion' must be a list of 4 or 5 numbers");
    for (size_t i = 0; i < d.size(); ++i) {
      try {
        c.distortion[i] = d[i].as<double>();
      } catch (const YAML::Exception&) {
        ThrowInputError(path, "camera field 'distortion' holds a non-number");
      }
    }
  } else {
    const char* keys[5] = {"k1", "k2", "p1", "p2", "k3"};
    for (int i = 0; i < 5; ++i)
      if (node[keys[i]]) c.distortion[i] = RequireNumber(node, keys[i], path);
  }
  try {
    c.Check();
  } catch (const std::invalid_argument& e) {
    ThrowInputError(path, e.what());
  }
  return c;
}

Camera LoadCameraYaml(const std::filesystem::path& path) {
  const std::string text = ReadTextFile(path);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    ThrowInputError(path, static_cast<size_t>(e.mark.line + 1), "malformed YAML: " + e.msg);
  }
  return ParseCameraNode(root, path);
}

YAML::Node CameraToYaml(const Camera& c) {
  YAML::Node n;
  n["width"] = c.width;
  n["height"] = c.height;
  n["fx"] = c.fx;
  n["fy"] = c.fy;
  n["cx"] = c.cx;
  n["cy"] = c.cy;
  YAML::Node d(YAML::NodeType::Sequence);
  for (double v : c.distortion) d.push_back(v);
  d.SetStyle(YAML::EmitterStyle::Flow);
  n["distortion"] = d;
  return n;
}

void WriteCameraYaml(const std::filesystem::path& path, const Camera& camera) {
  YAML::Emitter out;
  YAML::Node root;
  root["camera"] = CameraToYaml(camera);
  out << root;
  WriteTextFileAtomic(path, std::string(out.c_str()) + "\n");
}

}  // namespace ademono
