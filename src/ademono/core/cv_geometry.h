#pragma once
// Conversions between OpenCV's pose convention (Rodrigues rotation vector and translation, as
// returned by cv::solvePnP*) and ademono's Rigid3d.

#include <opencv2/core.hpp>

#include "ademono/core/geometry.h"

namespace ademono {

// The transform x -> R(rvec) x + tvec: for solvePnP's output, cam_from_object. rvec and tvec are
// 3-element CV_64F matrices.
Rigid3d RigidFromRodrigues(const cv::Mat& rvec, const cv::Mat& tvec);

}  // namespace ademono
