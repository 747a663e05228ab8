#pragma once
// Data passed to the Ceres optimisers. The optimisers know nothing about frames or maps: SLAM
// copies what it needs into these structs (under the map lock), solves without the lock, and
// writes results back.
//
// Observation model (ORB-SLAM2 RGB-D mode): a keypoint at undistorted pixel (u, v) with metric
// depth z is treated as a virtual stereo measurement (u, v, u_right = u - bf / z), bf being a
// virtual baseline times fx; without depth it is a plain (u, v) measurement. Residuals are scaled
// by 1 / sigma of the keypoint's pyramid level, so chi2 thresholds are in pixels^2 at level 0.
// When the depth has an error model (network depth), the u_right residual is instead scaled by
// `depth_inv_sigma` = 1 / sigma(u_right) = z^2 / (bf * sigma_z(z)): the depth then weighs what its
// uncertainty says, whatever the virtual baseline.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "ademono/core/geometry.h"

namespace ademono {

struct PinholeIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double bf = 0;  // virtual baseline (m) * fx, for the depth residual
};

struct ImageObservation {
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // undistorted
  double u_right = -1.0;                            // < 0: no depth, 2-dof residual
  double inv_sigma2 = 1.0;                          // 1 / sigma^2 of the keypoint's level
  double depth_inv_sigma = 0.0;  // > 0: weight of the u_right residual (error model)
  bool HasDepth() const { return u_right >= 0.0; }
  // Weight of the u_right residual: the error model's, else the pixel sigma's.
  double DepthWeight2() const {
    return depth_inv_sigma > 0.0 ? depth_inv_sigma * depth_inv_sigma : inv_sigma2;
  }
};

// chi2 thresholds at 95%: 2 dof (u, v) and 3 dof (u, v, u_right).
inline constexpr double kChi2Mono = 5.991;
inline constexpr double kChi2Stereo = 7.815;

}  // namespace ademono
