// ResolveFramePose (slam/tracking.h): a tracked frame's pose follows the keyframes around it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "ademono/slam/map.h"
#include "ademono/slam/tracking.h"
#include "frame_test_util.h"

namespace ademono {
namespace {

using testing_util::TestFeatures;

Rigid3d Pose(double angle, const Eigen::Vector3d& axis, const Eigen::Vector3d& translation) {
  Rigid3d m = Rigid3d::Identity();
  m.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  m.translation() = translation;
  return m;
}

double MaxDifference(const Rigid3d& a, const Rigid3d& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

// Two keyframes at t = 0 and t = 1 and a frame tracked between them at t = 0.25, anchored as
// tracking anchors it (its reference is the first keyframe).
struct Anchored {
  Map map;
  std::shared_ptr<KeyFrame> first, second;
  FrameRecord record;
  Rigid3d cam_from_world;

  Anchored() {
    const auto features = TestFeatures({{100, 100}}, {2.0f}, 3);
    Frame f0(0, 0, 0.0, features), f1(1, 4, 1.0, features);
    f0.cam_from_world = Pose(0.1, {0, 1, 0}, {0.0, 0.0, 0.0});
    f1.cam_from_world = Pose(0.3, {0, 1, 0}, {-0.4, 0.0, 0.1});
    first = map.CreateKeyFrame(f0);
    second = map.CreateKeyFrame(f1);
    cam_from_world = Pose(0.15, {0, 1, 0.1}, {-0.1, 0.01, 0.02});
    record.index = 1;
    record.timestamp = 0.25;
    record.tracked = true;
    record.reference = first.get();
    record.cam_from_reference = cam_from_world * first->cam_from_world.inverse();
    record.previous_keyframe = first.get();
    record.cam_from_previous = record.cam_from_reference;
    record.next_keyframe = second.get();
    record.cam_from_next = cam_from_world * second->cam_from_world.inverse();
  }
};

TEST(FramePoseTest, UntouchedKeyFramesGiveTheTrackedPose) {
  Anchored a;
  EXPECT_LT(MaxDifference(ResolveFramePose(a.record), a.cam_from_world), 1e-12);
}

TEST(FramePoseTest, TheFrameFollowsACorrectionOfTheWholeMapExactly) {
  Anchored a;
  const Rigid3d world_from_new = Pose(0.2, {1, 1, 0}, {0.3, -0.1, 0.05});
  a.first->cam_from_world = a.first->cam_from_world * world_from_new;
  a.second->cam_from_world = a.second->cam_from_world * world_from_new;
  EXPECT_LT(MaxDifference(ResolveFramePose(a.record), a.cam_from_world * world_from_new), 1e-12);
}

TEST(FramePoseTest, ACorrectionOfTheNextKeyFrameAloneMovesTheFrameByItsShareOfTime) {
  // The second keyframe's camera moves 4 cm along x in the world; the frame, a quarter of the
  // way from the first, moves 1 cm, where its reference keyframe alone would not move it at all.
  Anchored a;
  const Eigen::Vector3d centre_before = a.cam_from_world.inverse().translation();
  Rigid3d world_from_cam = a.second->cam_from_world.inverse();
  world_from_cam.translation() += Eigen::Vector3d(0.04, 0, 0);
  a.second->cam_from_world = world_from_cam.inverse();
  const Eigen::Vector3d moved =
      ResolveFramePose(a.record).inverse().translation() - centre_before;
  EXPECT_NEAR(moved.x(), 0.01, 1e-12);
  EXPECT_NEAR(moved.y(), 0.0, 1e-12);
  EXPECT_NEAR(moved.z(), 0.0, 1e-12);

  FrameRecord by_reference = a.record;
  by_reference.next_keyframe = nullptr;
  EXPECT_LT(MaxDifference(ResolveFramePose(by_reference), a.cam_from_world), 1e-12);
}

TEST(FramePoseTest, ACulledKeyFrameIsFollowedThroughItsParent) {
  // The first keyframe is culled after the frame: its parent carries the frame, as for the
  // reference keyframe (Map::ResolvePose).
  Anchored a;
  a.first->parent = a.second.get();
  a.first->cam_from_parent = a.first->cam_from_world * a.second->cam_from_world.inverse();
  a.first->bad = true;
  a.first->cam_from_world = Pose(1.0, {1, 0, 0}, {5, 5, 5});  // stale once culled
  EXPECT_LT(MaxDifference(ResolveFramePose(a.record), a.cam_from_world), 1e-12);
}

}  // namespace
}  // namespace ademono
