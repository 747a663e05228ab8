#include "ademono/core/cv_geometry.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <stdexcept>

namespace ademono {

Rigid3d RigidFromRodrigues(const cv::Mat& rvec, const cv::Mat& tvec) {
  if (rvec.total() != 3 || tvec.total() != 3 || rvec.depth() != CV_64F || tvec.depth() != CV_64F)
    throw std::invalid_argument("RigidFromRodrigues: rvec and tvec must be 3-vectors of double");
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Eigen::Matrix3d rotation;
  cv::cv2eigen(R, rotation);
  Rigid3d result = Rigid3d::Identity();
  result.linear() = rotation;
  result.translation() =
      Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  return result;
}

}  // namespace ademono
