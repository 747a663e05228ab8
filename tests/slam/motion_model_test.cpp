#include "ademono/slam/motion_model.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace ademono {
namespace {

Rigid3d Motion(double angle, const Eigen::Vector3d& axis, const Eigen::Vector3d& translation) {
  Rigid3d m = Rigid3d::Identity();
  m.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  m.translation() = translation;
  return m;
}

TEST(MotionModelTest, RecoversAConstantTranslationAndAConstantRotation) {
  const Rigid3d start = Motion(0.3, {1, 2, 3}, {0.5, -0.2, 1.0});
  for (const Rigid3d& step : {Motion(0, {0, 0, 1}, {0.01, -0.02, 0.005}),
                              Motion(0.02, {0.2, 1, 0.1}, {0, 0, 0})}) {
    Rigid3d pose = start;
    for (int k = 0; k < 5; ++k) pose = step * pose;
    const Rigid3d mean = MeanFrameMotion(start, pose, 5);
    EXPECT_LT((mean.matrix() - step.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(MotionModelTest, SpreadsOneFramesJumpOverTheSpan) {
  // Four frames still, then one 5 cm step: the mean is 1 cm a frame, the last step 5 cm.
  const Rigid3d start = Rigid3d::Identity();
  const Rigid3d end = Motion(0, {0, 0, 1}, {0.05, 0, 0}) * start;
  const Rigid3d mean = MeanFrameMotion(start, end, 5);
  EXPECT_NEAR(mean.translation().x(), 0.01, 1e-12);
  EXPECT_TRUE(mean.linear().isApprox(Eigen::Matrix3d::Identity()));
}

TEST(MotionModelTest, RejectsANonPositiveSpan) {
  EXPECT_THROW(MeanFrameMotion(Rigid3d::Identity(), Rigid3d::Identity(), 0),
               std::invalid_argument);
}

}  // namespace
}  // namespace ademono
