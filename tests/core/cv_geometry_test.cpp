#include "ademono/core/cv_geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace ademono {
namespace {

TEST(RigidFromRodriguesTest, QuarterTurnAboutZThenTranslation) {
  const cv::Mat rvec = (cv::Mat_<double>(3, 1) << 0, 0, M_PI / 2);
  const cv::Mat tvec = (cv::Mat_<double>(3, 1) << 1, 2, 3);
  const Rigid3d cam_from_object = RigidFromRodrigues(rvec, tvec);
  const Eigen::Vector3d x = cam_from_object * Eigen::Vector3d(1, 0, 0);
  EXPECT_NEAR(x.x(), 1.0, 1e-12);  // (0, 1, 0) + (1, 2, 3)
  EXPECT_NEAR(x.y(), 3.0, 1e-12);
  EXPECT_NEAR(x.z(), 3.0, 1e-12);
  // Same rotation as the exponential map of the rotation vector.
  EXPECT_LT((cam_from_object.linear() - ExpSO3(Eigen::Vector3d(0, 0, M_PI / 2))).norm(), 1e-12);
}

TEST(RigidFromRodriguesTest, RejectsWrongShapesAndTypes) {
  const cv::Mat ok = cv::Mat::zeros(3, 1, CV_64F);
  EXPECT_THROW(RigidFromRodrigues(cv::Mat::zeros(4, 1, CV_64F), ok), std::invalid_argument);
  EXPECT_THROW(RigidFromRodrigues(ok, cv::Mat::zeros(3, 1, CV_32F)), std::invalid_argument);
  EXPECT_NO_THROW(RigidFromRodrigues(ok, ok));
}

}  // namespace
}  // namespace ademono
