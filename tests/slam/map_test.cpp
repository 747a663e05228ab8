#include "ademono/slam/map.h"

#include <gtest/gtest.h>

#include "frame_test_util.h"

namespace ademono {
namespace {

using testing_util::TestFeatures;

TEST(MapTest, ErasingAKeyFrameThatHoldsTheLastReferenceToAPoint) {
  // A keyframe can still hold a point the map has already erased (it was in the keyframe but not
  // among the point's observations). Erasing the keyframe then drops the last owner of the point:
  // the point must stay alive until its bookkeeping is done (this was a use after free, found by
  // AddressSanitizer on the synthetic office).
  Map map;
  const auto features = TestFeatures({{100, 100}, {200, 150}}, {1.5f, 2.0f}, 3);
  Frame f0(0, 0, 0.0, features), f1(1, 1, 0.1, features);
  f0.cam_from_world = f1.cam_from_world = Rigid3d::Identity();
  auto kf0 = map.CreateKeyFrame(f0);
  auto kf1 = map.CreateKeyFrame(f1);  // the first keyframe is never erased; this one can be
  auto point = map.CreateMapPoint(Eigen::Vector3d(0, 0, 2), kf1.get(), 1);
  kf1->AddMapPoint(point, 0);
  map.ErasePoint(point.get());  // no observations: kf1 keeps its pointer
  ASSERT_EQ(point.use_count(), 2);
  point.reset();  // kf1 is now the only owner (no weak_ptr: it would keep the memory allocated)
  map.EraseKeyFrame(kf1.get());
  EXPECT_TRUE(kf1->bad);
  EXPECT_TRUE(kf1->map_points.empty());
  EXPECT_EQ(map.NumMapPoints(), 0u);
}

TEST(MapTest, ReplaceAndEraseKeepObservationsConsistent) {
  Map map;
  const auto f = TestFeatures({{100, 100}, {200, 150}}, {1.5f, 2.0f}, 3);
  Frame frame(0, 0, 0.0, f);
  frame.cam_from_world = Rigid3d::Identity();
  auto kf0 = map.CreateKeyFrame(frame);
  auto kf1 = map.CreateKeyFrame(frame);
  auto a = map.CreateMapPoint(Eigen::Vector3d(0, 0, 1.5), kf0.get(), 0);
  auto b = map.CreateMapPoint(Eigen::Vector3d(0, 0, 1.5), kf1.get(), 0);
  a->AddObservation(kf0.get(), 0);
  kf0->AddMapPoint(a, 0);
  b->AddObservation(kf1.get(), 0);
  kf1->AddMapPoint(b, 0);
  map.ReplacePoint(b.get(), a);
  EXPECT_TRUE(b->bad);
  EXPECT_EQ(MapPoint::Resolve(b), a);
  EXPECT_EQ(a->NumObservations(), 2);
  EXPECT_EQ(kf1->map_points[0], a);
  EXPECT_EQ(map.NumMapPoints(), 1u);
  kf1->UpdateConnections();
  map.EraseKeyFrame(kf1.get());
  EXPECT_TRUE(kf1->bad);
  EXPECT_EQ(a->NumObservations(), 1);
  EXPECT_EQ(map.NumKeyFrames(), 1u);
  map.EraseKeyFrame(kf0.get());  // the first keyframe stays
  EXPECT_FALSE(kf0->bad);
}

TEST(MapTest, ACulledKeyFrameKeepsItsPoseLinkButNotItsKeypoints) {
  // Memory grows with the map, not with the frames: culled keyframes drop their features, while
  // frames that referenced them still resolve their poses through the spanning tree.
  Map map;
  const auto features = TestFeatures({{100, 100}, {200, 150}}, {1.5f, 2.0f}, 3);
  Frame f0(0, 0, 0.0, features), f1(1, 1, 0.1, features);
  f0.cam_from_world = Rigid3d::Identity();
  f1.cam_from_world = Rigid3d::Identity();
  f1.cam_from_world->translation() = Eigen::Vector3d(0.1, 0, 0);
  auto kf0 = map.CreateKeyFrame(f0);
  auto kf1 = map.CreateKeyFrame(f1);
  kf1->parent = kf0.get();
  kf0->children.insert(kf1.get());
  ASSERT_EQ(kf1->F().Size(), 2u);
  ASSERT_EQ(kf1->map_points.size(), 2u);
  Rigid3d cam_from_kf1 = Rigid3d::Identity();
  cam_from_kf1.translation() = Eigen::Vector3d(0, 0.2, 0);
  const Rigid3d before = Map::ResolvePose(kf1.get(), cam_from_kf1);
  map.EraseKeyFrame(kf1.get());
  ASSERT_TRUE(kf1->bad);
  EXPECT_EQ(kf1->F().Size(), 0u);
  EXPECT_EQ(kf1->F().descriptors.rows, 0);
  // Nor its map point slots (16 bytes a keypoint, the bulk of a culled keyframe before).
  EXPECT_EQ(kf1->map_points.capacity(), 0u);
  EXPECT_EQ(kf1->ordered_connections.capacity(), 0u);
  EXPECT_TRUE(kf1->F().FeaturesInArea(100, 100, 50).empty());
  EXPECT_EQ(kf1->F().intrinsics.fx, features->intrinsics.fx);  // geometry kept
  EXPECT_TRUE(Map::ResolvePose(kf1.get(), cam_from_kf1).isApprox(before, 1e-12));
  EXPECT_EQ(features->Size(), 2u);  // the frame's own features are untouched
}

TEST(MapTest, APoseFollowsTheLocalScaleAroundItsKeyFrame) {
  // A frame's pose relative to its keyframe is measured in the map's units of that moment. When
  // local BA or a loop later rescales the map around the keyframe, the pose follows (and through
  // a culled keyframe, its parent's change after the cull), while a uniform Map::Rescale, which
  // the tracker applies to its records itself, leaves the measured change alone.
  Map map;
  std::vector<cv::Point2f> pixels;
  std::vector<float> depths;
  for (int i = 0; i < 20; ++i) {
    pixels.emplace_back(100.f + 20.f * static_cast<float>(i), 120.f);
    depths.push_back(2.f);
  }
  const auto features = TestFeatures(pixels, depths, 5);
  Frame f0(0, 0, 0.0, features), f1(1, 1, 0.1, features);
  f0.cam_from_world = Rigid3d::Identity();
  f1.cam_from_world = Rigid3d::Identity();
  f1.cam_from_world->translation() = Eigen::Vector3d(-0.1, 0, 0);  // centre at x = 0.1
  auto kf0 = map.CreateKeyFrame(f0);
  auto kf1 = map.CreateKeyFrame(f1);
  kf1->parent = kf0.get();
  kf0->children.insert(kf1.get());
  for (size_t i = 0; i < pixels.size(); ++i) {
    const double x = static_cast<double>(i);
    auto p = map.CreateMapPoint(Eigen::Vector3d(0.05 * x - 0.5, 0.1, 2.0 + 0.1 * x), kf1.get(), 1);
    p->AddObservation(kf0.get(), i);
    p->AddObservation(kf1.get(), i);
    kf0->AddMapPoint(p, i);
    kf1->AddMapPoint(p, i);
  }
  kf0->UpdateConnections();
  kf1->UpdateConnections();
  auto scale_about = [&map](const Eigen::Vector3d& centre, double factor) {
    for (const auto& [id, p] : map.MapPoints())
      p->position = centre + factor * (p->position - centre);
    map.NoteStructureChange();
  };

  const int snapshot = kf1->SnapshotScale(map.StructureVersion());
  EXPECT_EQ(kf1->SnapshotScale(map.StructureVersion()), snapshot);  // nothing moved: the same one
  EXPECT_DOUBLE_EQ(kf1->LocalScaleSince(snapshot), 1.0);
  Rigid3d cam_from_kf1 = Rigid3d::Identity();
  cam_from_kf1.translation() = Eigen::Vector3d(0, 0.2, 0.05);
  const Rigid3d rigid = Map::ResolvePose(kf1.get(), cam_from_kf1);

  scale_about(kf1->CameraCenter(), 1.1);
  EXPECT_NEAR(kf1->LocalScaleSince(snapshot), 1.1, 1e-6);
  EXPECT_TRUE(Map::ResolvePose(kf1.get(), cam_from_kf1).isApprox(rigid, 1e-12));
  Rigid3d expected = cam_from_kf1;
  expected.translation() *= 1.1;
  EXPECT_TRUE(Map::ResolvePose(kf1.get(), cam_from_kf1, snapshot)
                  .isApprox(expected * kf1->cam_from_world, 1e-6));
  EXPECT_NE(kf1->SnapshotScale(map.StructureVersion()), snapshot);  // moved: a new one

  map.Rescale(2.0);  // uniform: not a change of the local scale
  EXPECT_NEAR(kf1->LocalScaleSince(snapshot), 1.1, 1e-6);
  cam_from_kf1.translation() *= 2.0;  // as the tracker rescales its records

  map.EraseKeyFrame(kf1.get());
  ASSERT_TRUE(kf1->bad);
  ASSERT_EQ(kf1->parent, kf0.get());
  EXPECT_NEAR(kf1->LocalScaleSince(snapshot), 1.1, 1e-6);  // kept from the cull
  scale_about(kf0->CameraCenter(), 1.25);
  EXPECT_NEAR(kf0->LocalScaleSince(kf1->parent_snapshot), 1.25, 1e-6);
  Rigid3d through_parent = cam_from_kf1;
  through_parent.translation() *= 1.1;
  through_parent = through_parent * kf1->cam_from_parent;
  through_parent.translation() *= 1.25;
  EXPECT_TRUE(Map::ResolvePose(kf1.get(), cam_from_kf1, snapshot)
                  .isApprox(through_parent * kf0->cam_from_world, 1e-6));
}

}  // namespace
}  // namespace ademono
