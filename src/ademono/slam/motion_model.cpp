#include "ademono/slam/motion_model.h"

#include <Eigen/Geometry>
#include <stdexcept>

namespace ademono {

Rigid3d MeanFrameMotion(const Rigid3d& cam_old_from_world, const Rigid3d& cam_new_from_world,
                        double frames) {
  if (!(frames > 0)) throw std::invalid_argument("MeanFrameMotion: frames must be positive");
  const Rigid3d span = cam_new_from_world * cam_old_from_world.inverse();
  const Eigen::AngleAxisd rotation(span.linear());
  Rigid3d step = Rigid3d::Identity();
  step.linear() = Eigen::AngleAxisd(rotation.angle() / frames, rotation.axis()).toRotationMatrix();
  step.translation() = span.translation() / frames;
  return step;
}

}  // namespace ademono
