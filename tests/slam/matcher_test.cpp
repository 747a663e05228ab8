#include "ademono/slam/matcher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "ademono/core/worker_pool.h"
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

// Keypoints without depth, as a monocular keyframe has them, for the triangulation search.
std::shared_ptr<const FrameFeatures> SearchFeatures(const Camera& camera,
                                                    std::shared_ptr<ScalePyramid> pyramid,
                                                    const std::vector<cv::KeyPoint>& kps,
                                                    const cv::Mat& desc) {
  return MakeFrameFeatures(camera, std::move(pyramid), 0.08, 3.2, kps, desc,
                           std::vector<float>(kps.size(), -1.f), {}, true, true);
}

// Two keyframes of `map` made of these keypoints: the first at the origin, the second at
// `cam2_from_world`.
std::pair<std::shared_ptr<KeyFrame>, std::shared_ptr<KeyFrame>> TwoKeyFrames(
    Map& map, const Camera& camera, const std::shared_ptr<ScalePyramid>& pyramid,
    const std::vector<cv::KeyPoint>& kps1, const cv::Mat& desc1,
    const std::vector<cv::KeyPoint>& kps2, const cv::Mat& desc2, const Rigid3d& cam2_from_world) {
  Frame frame1(0, 0, 0.0, SearchFeatures(camera, pyramid, kps1, desc1));
  Frame frame2(1, 1, 0.1, SearchFeatures(camera, pyramid, kps2, desc2));
  frame1.cam_from_world = Rigid3d::Identity();
  frame2.cam_from_world = cam2_from_world;
  return {map.CreateKeyFrame(frame1), map.CreateKeyFrame(frame2)};
}

// Triangulation's epipolar search (LineSearchGrid's band) finds every pair a keypoint off its
// epipolar line by up to its pyramid level's tolerance, the top level's too, and no distractor.
TEST(MatcherTest, TriangulationSearchFindsPairsWithinEachLevelsEpipolarBand) {
  const Camera camera = testing_util::TestCamera();
  auto pyramid = std::make_shared<ScalePyramid>(ScalePyramid::Make(8, 1.2f));
  // Camera 2 one metre to the side: the epipolar lines are the image rows, the epipole far away.
  const Rigid3d cam2_from_world(Eigen::Translation3d(-1.0, 0.0, 0.0));
  cv::RNG rng(11);
  std::vector<cv::KeyPoint> kps1, kps2;
  const int pairs = 300, distractors = 600;
  cv::Mat desc1(pairs, 32, CV_8UC1), desc2(pairs + distractors, 32, CV_8UC1);
  rng.fill(desc1, cv::RNG::UNIFORM, 0, 256);
  rng.fill(desc2, cv::RNG::UNIFORM, 0, 256);
  for (int i = 0; i < pairs; ++i) {
    const Eigen::Vector3d p(rng.uniform(-1.5, 1.5), rng.uniform(-1.0, 1.0), rng.uniform(3.0, 8.0));
    const Eigen::Vector3d q = cam2_from_world * p;
    const int octave = i % 8;
    // Off the line by 0.9x the level's tolerance (sqrt(3.84 sigma^2)), alternately up and down.
    const float off = 0.9f * std::sqrt(3.84f * pyramid->level_sigma2[octave]) * (i % 2 ? 1 : -1);
    kps1.emplace_back(cv::Point2f(585 * p.x() / p.z() + 320, 585 * p.y() / p.z() + 240), 31.f, 0.f,
                      1.f, octave);
    kps2.emplace_back(cv::Point2f(585 * q.x() / q.z() + 320, 585 * q.y() / q.z() + 240 + off), 31.f,
                      0.f, 1.f, octave);
    desc1.row(i).copyTo(desc2.row(i));  // the same point, the same descriptor
  }
  for (int j = 0; j < distractors; ++j)
    kps2.emplace_back(cv::Point2f(rng.uniform(0.f, 640.f), rng.uniform(0.f, 480.f)), 31.f, 0.f, 1.f,
                      j % 8);
  Map map;
  const auto [kf1, kf2] =
      TwoKeyFrames(map, camera, pyramid, kps1, desc1, kps2, desc2, cam2_from_world);
  std::vector<std::pair<size_t, size_t>> matches;
  EXPECT_EQ(Matcher(0.8f, false).SearchForTriangulation(*kf1, *kf2, 0.0, matches), pairs);
  for (const auto& [i, j] : matches) EXPECT_EQ(i, j);

  // A keypoint just outside its level's band is not matched.
  kps2[7].pt.y += 0.25f * std::sqrt(3.84f * pyramid->level_sigma2[7]);  // 1.15x the tolerance
  Frame moved(2, 2, 0.2, SearchFeatures(camera, pyramid, kps2, desc2));
  moved.cam_from_world = cam2_from_world;
  const auto kf3 = map.CreateKeyFrame(moved);
  matches.clear();
  EXPECT_EQ(Matcher(0.8f, false).SearchForTriangulation(*kf1, *kf3, 0.0, matches), pairs - 1);
  for (const auto& [i, j] : matches) EXPECT_NE(i, 7u);
}

// With a helper thread scanning half of k1's keypoints, the search returns the same pairs in the
// same order, ties included: k1's second half repeats keypoints of its first half (same pixel,
// same descriptor), so every k2 keypoint is wanted by two k1 keypoints, one in each half, and the
// lower index must win as in a scan in index order.
TEST(MatcherTest, TriangulationSearchWithAHelperIsTheSameToTheBit) {
  const Camera camera = testing_util::TestCamera();
  auto pyramid = std::make_shared<ScalePyramid>(ScalePyramid::Make(8, 1.2f));
  const Rigid3d cam2_from_world(Eigen::Translation3d(-1.0, 0.0, 0.0));
  cv::RNG rng(5);
  const int pairs = 250;
  std::vector<cv::KeyPoint> kps1, kps2;
  cv::Mat desc1(2 * pairs, 32, CV_8UC1), desc2(pairs, 32, CV_8UC1);
  rng.fill(desc2, cv::RNG::UNIFORM, 0, 256);
  for (int i = 0; i < pairs; ++i) {
    const Eigen::Vector3d p(rng.uniform(-1.5, 1.5), rng.uniform(-1.0, 1.0), rng.uniform(3.0, 8.0));
    const Eigen::Vector3d q = cam2_from_world * p;
    kps1.emplace_back(cv::Point2f(585 * p.x() / p.z() + 320, 585 * p.y() / p.z() + 240), 31.f, 0.f,
                      1.f, i % 4);
    kps2.emplace_back(cv::Point2f(585 * q.x() / q.z() + 320, 585 * q.y() / q.z() + 240), 31.f, 0.f,
                      1.f, i % 4);
    desc2.row(i).copyTo(desc1.row(i));
    // A few bits flipped in some of the copies: not every tie is exact.
    desc2.row(i).copyTo(desc1.row(pairs + i));
    if (i % 3 == 0) desc1.at<uchar>(pairs + i, i % 32) ^= 0x5;
  }
  for (int i = 0; i < pairs; ++i) kps1.push_back(kps1[static_cast<size_t>(i)]);
  Map map;
  const auto [kf1, kf2] =
      TwoKeyFrames(map, camera, pyramid, kps1, desc1, kps2, desc2, cam2_from_world);
  const Matcher matcher(0.8f, false);
  std::vector<std::pair<size_t, size_t>> alone, helped;
  // Every k2 keypoint goes to the first-half keypoint: as near as its copy, or nearer.
  const int n = matcher.SearchForTriangulation(*kf1, *kf2, 0.0, alone);
  EXPECT_EQ(n, pairs);
  for (const auto& [i, j] : alone) EXPECT_EQ(i, j);
  WorkerPool helper(1);
  EXPECT_EQ(matcher.SearchForTriangulation(*kf1, *kf2, 0.0, helped, &helper), n);
  EXPECT_EQ(helped, alone);
}

}  // namespace
}  // namespace ademono
