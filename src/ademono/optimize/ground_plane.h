#pragma once
// The ground plane under a forward-looking camera, from 3D points in the camera frame (x right,
// y down, z forward), and the camera's height above it. A vehicle's camera height is known
// (KITTI: 1.65 m), so the ratio of the configured to the measured height is the scale error of a
// network's depth: the usual remedy for monocular driving odometry, here applied to a metric
// network's bias (slam/tracking.h, depth.camera_height).
//
// RANSAC over planes through three points whose normal lies within max_tilt_deg of the camera's
// up axis (-y), inliers within inlier_ratio * height of the plane; the best plane is refitted by
// maximum likelihood for depth errors proportional to depth (ground_plane.cpp). A raised surface
// as populous as the road beside it (a sidewalk 15 cm up) draws a plane through both: callers
// pass a corridor ahead. Deterministic: a fixed-seed std::mt19937, taken modulo (the engine's
// sequence is fixed by the standard, unlike the distributions).

#include <Eigen/Core>

#include <vector>

namespace ademono {

struct GroundPlaneOptions {
  double max_tilt_deg = 15.0;     // the plane's normal within this angle of the camera's up axis
  double inlier_ratio = 0.05;     // inlier distance as a fraction of the candidate's height
  int min_inliers = 50;           // fewer: no estimate
  double min_inlier_share = 0.2;  // of the points given
  int iterations = 300;
  void Check() const;  // throws std::invalid_argument
};

struct GroundPlane {
  bool valid = false;
  Eigen::Vector3d normal =
      Eigen::Vector3d(0, -1, 0);  // unit, pointing from the plane to the camera
  double height = 0.0;            // camera's distance above the plane, in the points' units
  int num_inliers = 0;
};

// `points_cam`: candidate ground points in the camera frame (callers pass those below the
// horizon and off dynamic objects). Points on other surfaces are outliers.
GroundPlane EstimateGroundPlane(const std::vector<Eigen::Vector3d>& points_cam,
                                const GroundPlaneOptions& options = {});

}  // namespace ademono
