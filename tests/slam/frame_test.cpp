#include "ademono/slam/frame.h"

#include <gtest/gtest.h>

#include "ademono/slam/map.h"
#include "ademono/slam/matcher.h"

namespace ademono {
namespace {

Camera TestCamera() {
  Camera camera;
  camera.width = 640;
  camera.height = 480;
  camera.fx = camera.fy = 585;
  camera.cx = 320;
  camera.cy = 240;
  return camera;
}

std::shared_ptr<const FrameFeatures> Features(const std::vector<cv::Point2f>& points,
                                              const std::vector<float>& depth, uint8_t seed) {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors(static_cast<int>(points.size()), 32, CV_8UC1);
  for (size_t i = 0; i < points.size(); ++i) {
    keypoints.emplace_back(points[i], 31.f, 10.f * i, 1.f, 0);
    // The same (seed, i) always gives the same random descriptor.
    cv::RNG rng(1000 * seed + i);
    cv::Mat row = descriptors.row(static_cast<int>(i));
    rng.fill(row, cv::RNG::UNIFORM, 0, 256);
  }
  auto pyramid = std::make_shared<ScalePyramid>(ScalePyramid::Make(8, 1.2f));
  return MakeFrameFeatures(TestCamera(), pyramid, 0.08, 3.2, keypoints, descriptors, depth);
}

TEST(FrameFeaturesTest, GridSearchAndVirtualRightCoordinate) {
  const auto f =
      Features({{100, 100}, {105, 102}, {300, 200}, {639, 479}}, {1.0f, -1.f, 2.0f, 0.f}, 1);
  EXPECT_EQ(f->FeaturesInArea(102, 101, 10), (std::vector<size_t>{0, 1}));
  EXPECT_EQ(f->FeaturesInArea(300, 200, 2), (std::vector<size_t>{2}));
  EXPECT_TRUE(f->FeaturesInArea(300, 200, 2, 1, 3).empty());  // all on level 0
  EXPECT_EQ(f->FeaturesInArea(638, 478, 4), (std::vector<size_t>{3}));
  EXPECT_NEAR(f->u_right[0], 100 - 585 * 0.08 / 1.0, 1e-3);
  EXPECT_LT(f->u_right[1], 0);
  EXPECT_LT(f->u_right[3], 0);
  EXPECT_TRUE(f->IsClose(0));
  EXPECT_FALSE(f->IsClose(1));
  const Eigen::Vector3d p = f->UnprojectCamera(2);
  EXPECT_NEAR(p.z(), 2.0, 1e-9);
  EXPECT_NEAR(p.x(), (300 - 320) * 2.0 / 585, 1e-9);
}

TEST(MapTest, ErasingAKeyFrameThatHoldsTheLastReferenceToAPoint) {
  // A keyframe can still hold a point the map has already erased (it was in the keyframe but not
  // among the point's observations). Erasing the keyframe then drops the last owner of the point:
  // the point must stay alive until its bookkeeping is done (this was a use after free, found by
  // AddressSanitizer on the synthetic office).
  Map map;
  const auto features = Features({{100, 100}, {200, 150}}, {1.5f, 2.0f}, 3);
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
  EXPECT_EQ(kf1->map_points[0], nullptr);
  EXPECT_EQ(map.NumMapPoints(), 0u);
}

TEST(MatcherTest, ProjectionSearchFindsTheSameDescriptorsUnderSmallMotion) {
  Map map;
  const auto f0 =
      Features({{100, 100}, {200, 150}, {400, 300}, {500, 400}}, {1.5f, 2.0f, 2.5f, 1.8f}, 7);
  Frame first(0, 0, 0.0, f0);
  first.cam_from_world = Rigid3d::Identity();
  auto kf = map.CreateKeyFrame(first);
  for (size_t i = 0; i < f0->Size(); ++i) {
    auto p = map.CreateMapPoint(f0->UnprojectCamera(i), kf.get(), 0);
    p->AddObservation(kf.get(), i);
    kf->AddMapPoint(p, i);
    p->ComputeDistinctiveDescriptor();
    p->UpdateNormalAndDepth();
    first.map_points[i] = p;
  }
  // The next frame sees the same points shifted by 3 px (same descriptors).
  const auto f1 =
      Features({{103, 100}, {203, 150}, {403, 300}, {503, 400}}, {1.5f, 2.0f, 2.5f, 1.8f}, 7);
  Frame second(1, 1, 1 / 30.0, f1);
  second.cam_from_world = Rigid3d::Identity();
  const Matcher matcher(0.9f, true);
  EXPECT_EQ(matcher.SearchByProjection(second, first, 15.f), 4);
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ(second.map_points[i], first.map_points[i]);
  // A 1 px window misses them.
  Frame third(2, 2, 2 / 30.0, f1);
  third.cam_from_world = Rigid3d::Identity();
  EXPECT_EQ(matcher.SearchByProjection(third, first, 0.5f), 0);
  // Descriptor search against the keyframe finds them regardless of the pose.
  std::vector<std::shared_ptr<MapPoint>> matches;
  EXPECT_EQ(Matcher(0.9f, false).SearchByDescriptor(*kf, third, matches), 4);
}

TEST(MapTest, ReplaceAndEraseKeepObservationsConsistent) {
  Map map;
  const auto f = Features({{100, 100}, {200, 150}}, {1.5f, 2.0f}, 3);
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

}  // namespace
}  // namespace ademono
