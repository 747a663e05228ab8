#pragma once
// Pinhole camera with radial-tangential (OpenCV "plumb bob") distortion.
//
// Contract:
// - Pixel coordinates: (0, 0) is the centre of the top-left pixel; u to the right, v down.
// - Camera frame: x right, y down, z forward (optical axis). Depth is the z coordinate in metres.
// - Project(): camera-frame point -> distorted pixel. ProjectUndistorted(): ignores distortion.
// - Undistort(): distorted pixel -> undistorted pixel (same fx, fy, cx, cy), iterative inverse.
// - Unproject(): undistorted pixel and depth -> camera-frame point.
// Distortion coefficients are (k1, k2, p1, p2, k3), all zero for an ideal pinhole.

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <yaml-cpp/yaml.h>

namespace ademono {

struct Camera {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::array<double, 5> distortion{0, 0, 0, 0, 0};  // k1, k2, p1, p2, k3

  bool HasDistortion() const;
  // Throws std::invalid_argument describing the first bad field.
  void Check() const;

  Eigen::Matrix3d K() const;
  cv::Mat KMat() const;          // CV_64F 3x3
  cv::Mat DistortionMat() const; // CV_64F 1x5

  Eigen::Vector2d ProjectUndistorted(const Eigen::Vector3d& point_cam) const;
  Eigen::Vector2d Project(const Eigen::Vector3d& point_cam) const;
  Eigen::Vector2d Distort(const Eigen::Vector2d& undistorted_px) const;
  Eigen::Vector2d Undistort(const Eigen::Vector2d& distorted_px) const;
  std::vector<cv::Point2f> Undistort(const std::vector<cv::Point2f>& distorted_px) const;
  Eigen::Vector3d Unproject(const Eigen::Vector2d& undistorted_px, double depth) const;

  bool InImage(const Eigen::Vector2d& px, double border = 0.0) const;

  // An undistorted pinhole with square pixels (fx = fy = focal).
  static Camera Pinhole(int width, int height, double focal, double cx, double cy);

  // Same camera at a different resolution (intrinsics scaled).
  Camera Scaled(double scale_x, double scale_y) const;
};

// Camera YAML (the `camera:` node or the file root):
//   width: 640
//   height: 480
//   fx: 525.0
//   fy: 525.0
//   cx: 319.5
//   cy: 239.5
//   distortion: [k1, k2, p1, p2, k3]   # optional, default zeros (also k1.. as separate keys)
// Missing or malformed fields raise InputError naming the file and the field.
Camera LoadCameraYaml(const std::filesystem::path& path);
Camera ParseCameraNode(const YAML::Node& node, const std::filesystem::path& path_for_errors);
YAML::Node CameraToYaml(const Camera& camera);
void WriteCameraYaml(const std::filesystem::path& path, const Camera& camera);

}  // namespace ademono
