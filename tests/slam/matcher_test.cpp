#include "ademono/slam/matcher.h"

#include <gtest/gtest.h>

#include <vector>

#include "frame_test_util.h"

namespace ademono {
namespace {

using testing_util::TestFeatures;

// Makes `frame` (at the origin) a keyframe and every one of its keypoints a map point.
std::shared_ptr<KeyFrame> MapEveryKeypoint(Map& map, Frame& frame) {
  frame.cam_from_world = Rigid3d::Identity();
  auto kf = map.CreateKeyFrame(frame);
  for (size_t i = 0; i < frame.F().Size(); ++i) {
    auto p = map.CreateMapPoint(frame.F().UnprojectCamera(i), kf.get(), 0);
    p->AddObservation(kf.get(), i);
    kf->AddMapPoint(p, i);
    p->ComputeDistinctiveDescriptor();
    p->UpdateNormalAndDepth();
    frame.map_points[i] = p;
  }
  return kf;
}

TEST(MatcherTest, ProjectionSearchFindsTheSameDescriptorsUnderSmallMotion) {
  Map map;
  const auto f0 =
      TestFeatures({{100, 100}, {200, 150}, {400, 300}, {500, 400}}, {1.5f, 2.0f, 2.5f, 1.8f}, 7);
  Frame first(0, 0, 0.0, f0);
  const auto kf = MapEveryKeypoint(map, first);
  // The next frame sees the same points shifted by 3 px (same descriptors).
  const auto f1 =
      TestFeatures({{103, 100}, {203, 150}, {403, 300}, {503, 400}}, {1.5f, 2.0f, 2.5f, 1.8f}, 7);
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

// FindByProjection (the geometric test's look into the frame before a keyframe) returns the
// matching keypoint within the window, also one that already has a map point, and writes nothing.
TEST(MatcherTest, FindByProjectionReturnsTheKeypointWithinTheWindowOnly) {
  Map map;
  const auto f0 = TestFeatures({{100, 100}, {200, 150}, {400, 300}}, {1.5f, 2.0f, 2.5f}, 7);
  Frame first(0, 0, 0.0, f0);
  MapEveryKeypoint(map, first);
  const auto f1 = TestFeatures({{103, 100}, {200, 154}, {400, 300}}, {1.5f, 2.0f, 2.5f}, 7);
  Frame second(1, 1, 1 / 30.0, f1);
  second.cam_from_world = Rigid3d::Identity();
  second.map_points[2] = first.map_points[2];
  const Matcher matcher(0.8f, false);
  for (size_t i = 0; i < 3; ++i) {
    ProjectionPrediction prediction;
    ASSERT_TRUE(second.InFrustum(*first.map_points[i], 0.5f, &prediction));
    // Shifted 3 / 4 / 0 px: a 6 px window finds each, a 2 px window only the one in place.
    EXPECT_EQ(matcher.FindByProjection(second, *first.map_points[i], prediction, 6.f),
              static_cast<int>(i));
    EXPECT_EQ(matcher.FindByProjection(second, *first.map_points[i], prediction, 2.f),
              i == 2 ? 2 : -1);
  }
  EXPECT_EQ(second.map_points[0], nullptr);
  EXPECT_EQ(second.map_points[2], first.map_points[2]);
}

// The rotation check (feature/matching.h's RotationHistogram) drops a match whose keypoint turned
// against all the others, and only with check_orientation.
TEST(MatcherTest, RotationCheckDropsTheMatchThatTurnedAgainstTheOthers) {
  Map map;
  std::vector<cv::Point2f> points, shifted;
  std::vector<float> depths, angles, turned;
  for (int i = 0; i < 12; ++i) {
    points.emplace_back(60.f + 45.f * i, 100.f + 25.f * i);
    shifted.emplace_back(points.back().x + 2.f, points.back().y);
    depths.push_back(1.5f + 0.1f * i);
    angles.push_back(20.f * i);
    turned.push_back(i == 5 ? 20.f * i + 90.f : 20.f * i);
  }
  const auto f0 = TestFeatures(points, depths, 9, angles);
  Frame first(0, 0, 0.0, f0);
  const auto kf = MapEveryKeypoint(map, first);
  const auto f1 = TestFeatures(shifted, depths, 9, turned);
  Frame checked(1, 1, 1 / 30.0, f1), unchecked(2, 2, 1 / 30.0, f1);
  checked.cam_from_world = unchecked.cam_from_world = Rigid3d::Identity();
  EXPECT_EQ(Matcher(0.9f, true).SearchByProjection(checked, first, 15.f), 11);
  EXPECT_EQ(checked.map_points[5], nullptr);
  EXPECT_EQ(checked.map_points[4], first.map_points[4]);
  EXPECT_EQ(Matcher(0.9f, false).SearchByProjection(unchecked, first, 15.f), 12);
  std::vector<std::shared_ptr<MapPoint>> matches;
  EXPECT_EQ(Matcher(0.9f, true).SearchByDescriptor(*kf, checked, matches), 11);
  EXPECT_EQ(matches[5], nullptr);
}

}  // namespace
}  // namespace ademono
