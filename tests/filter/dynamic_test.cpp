#include "ademono/filter/dynamic.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "filter_test_util.h"

namespace ademono {
namespace {

using filter_test::TestCamera;

Detection Det(int class_id, float x, float y, float w, float h) {
  Detection d;
  d.class_id = class_id;
  d.class_name = class_id == 0 ? "person" : "vehicle";
  d.score = 0.9f;
  d.box = cv::Rect2f(x, y, w, h);
  return d;
}

cv::KeyPoint Kp(float x, float y) { return cv::KeyPoint(x, y, 31.f); }

// Random, well separated 32-byte descriptors (pairwise distances around 128).
cv::Mat RandomDescriptors(int rows, uint32_t seed) {
  std::mt19937 rng(seed);
  cv::Mat d(rows, 32, CV_8UC1);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < 32; ++c) d.at<uchar>(r, c) = static_cast<uchar>(rng() & 0xFF);
  return d;
}

void FlipBits(cv::Mat& descriptors, int row, int bits) {
  for (int b = 0; b < bits; ++b)
    descriptors.at<uchar>(row, b / 8) ^= static_cast<uchar>(1 << (b % 8));
}

TEST(GrowDynamicBoxesTest, GrowthClippingSizeClassAndClassFilter) {
  const std::vector<Detection> dets{
      Det(0, 100, 100, 30, 40),    // person, area 1200 / 307200 = 0.4% -> small; diag 50 -> d = 1
      Det(2, 300, 200, 200, 200),  // car, 13% -> large
      Det(56, 10, 10, 300, 300),   // chair: not a dynamic class
      Det(7, 600, 400, 100, 100),  // truck reaching past the image corner: clipped
  };
  const std::vector<GrownBox> boxes = GrowDynamicBoxes(dets, cv::Size(640, 480), DynamicParams{});
  ASSERT_EQ(boxes.size(), 3u);
  EXPECT_TRUE(boxes[0].small);
  EXPECT_EQ(boxes[0].detection_index, 0);
  EXPECT_FLOAT_EQ(boxes[0].box.x, 99.f);
  EXPECT_FLOAT_EQ(boxes[0].box.y, 99.f);
  EXPECT_FLOAT_EQ(boxes[0].box.width, 32.f);
  EXPECT_FLOAT_EQ(boxes[0].box.height, 42.f);
  EXPECT_FALSE(boxes[1].small);
  EXPECT_EQ(boxes[2].detection_index, 3);
  EXPECT_TRUE(boxes[2].small);  // 10000 / 307200 = 3.3% < 5%
  const double d = 0.02 * std::hypot(100.0, 100.0);
  EXPECT_NEAR(boxes[2].box.x, 600 - d, 1e-4);
  EXPECT_FLOAT_EQ(boxes[2].box.x + boxes[2].box.width, 640.f);
  EXPECT_FLOAT_EQ(boxes[2].box.y + boxes[2].box.height, 480.f);
  EXPECT_TRUE(InsideBox(cv::Rect2f(0, 0, 10, 10), cv::Point2f(0, 9.99f)));
  EXPECT_FALSE(InsideBox(cv::Rect2f(0, 0, 10, 10), cv::Point2f(10, 5)));
}

DynamicInput MakeInput(const std::vector<cv::KeyPoint>& cur, const cv::Mat& cur_desc,
                       const std::vector<Detection>& detections,
                       const PreviousFrameFeatures& previous, const Camera& camera) {
  DynamicInput in;
  in.keypoints = &cur;
  in.descriptors = &cur_desc;
  in.detections = &detections;
  in.previous = &previous;
  in.camera = &camera;
  return in;
}

// A scene with one small and one large dynamic box, background points moving by (2, 1) between
// frames, and large-box points exercising each branch of the two-stage test.
struct Scene {
  Camera camera = TestCamera();
  std::vector<Detection> detections{Det(0, 100, 100, 30, 40), Det(2, 300, 200, 200, 200)};
  std::vector<cv::KeyPoint> cur, prev;
  cv::Mat cur_desc, prev_desc;
  PreviousFrameFeatures previous;
  Rigid3d predicted = Rigid3d::Identity();

  // Indices of the current keypoints.
  enum : int {
    kSmallInside = 0,  // in the grown small box, outside the original box
    kSmallOutside,     // just outside the grown small box: background
    kBg1,
    kBg2,
    kBg3,             // background, exact descriptor matches, moving (2, 1)
    kBgOutlier,       // background moving (40, 0) but with a worse descriptor match (t = 3)
    kLargeStatic,     // in the large box, moves like the background, projects exactly
    kLargeStage1,     // in the large box, moves (20, 1)
    kLargeStage2,     // moves like the background, world point projects 10 px away
    kLargeNoWorld,    // moves like the background, no world point
    kLargeUnmatched,  // descriptor matches nothing in the previous frame
    kLargeNearProj,   // projects 3 px away (< d_min 4)
    kLargeBehind,     // world point behind the predicted camera
    kCount
  };

  Scene() {
    const cv::Point2f bg(2, 1);
    const std::vector<cv::Point2f> cur_pts{
        {99.5f, 99.5f}, {98.5f, 120}, {20, 20},   {600, 30},  {50, 400},  {200, 50}, {350, 250},
        {400, 300},     {450, 350},   {320, 380}, {480, 220}, {360, 300}, {420, 240}};
    const std::vector<cv::Point2f> motion{bg,      bg, bg, bg, bg, {40, 0}, bg,
                                          {20, 1}, bg, bg, bg, bg, bg};
    cur_desc = RandomDescriptors(kCount, 7);
    prev_desc = cur_desc.clone();
    FlipBits(prev_desc, kBgOutlier, 12);  // still matched, but the worst background match
    FlipBits(prev_desc, kBg3, 3);         // distance 3: among the three best
    prev_desc.row(kLargeUnmatched).setTo(0);
    cur_desc.row(kLargeUnmatched).setTo(0xFF);  // 256 bits from its old self
    for (int i = 0; i < kCount; ++i) {
      cur.push_back(Kp(cur_pts[i].x, cur_pts[i].y));
      prev.push_back(Kp(cur_pts[i].x - motion[i].x, cur_pts[i].y - motion[i].y));
    }
    previous.keypoints = prev;
    previous.descriptors = prev_desc;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    previous.points_world.assign(kCount, Eigen::Vector3d(nan, nan, nan));
    auto world_at = [&](float u, float v) { return camera.Unproject(Eigen::Vector2d(u, v), 2.0); };
    previous.points_world[kLargeStatic] = world_at(350, 250);
    previous.points_world[kLargeStage2] = world_at(460, 350);  // 10 px right of the observation
    previous.points_world[kLargeNearProj] = world_at(363, 300);
    previous.points_world[kLargeBehind] = Eigen::Vector3d(0, 0, -2);
    // kLargeStage1 would project exactly: stage 1 alone must catch it.
    previous.points_world[kLargeStage1] = world_at(400, 300);
  }

  DynamicInput Input() const {
    DynamicInput in = MakeInput(cur, cur_desc, detections, previous, camera);
    in.predicted_cam_from_world = predicted;
    return in;
  }
};

// The paper's rule: every point in a small box is dropped (the tests below check its branches).
DynamicParams Params() {
  DynamicParams p;
  p.background_matches_t = 3;
  p.judge_small_boxes = false;
  return p;
}

TEST(RemoveDynamicPointsTest, JudgedSmallBoxesKeepPointsThatMoveWithTheCamera) {
  // Judged like a large box (judge_small_boxes; off by default), a small box's point that moves
  // like the background stays kept (a far parked car); moved by (20, 1) it fails stage 1 (a far
  // moving car).
  Scene s;
  DynamicParams p = Params();
  p.judge_small_boxes = true;
  EXPECT_FALSE(DynamicParams{}.judge_small_boxes);
  const DynamicResult r = RemoveDynamicPoints(s.Input(), p);
  EXPECT_EQ(r.labels[Scene::kSmallInside], PointLabel::kKept);
  // The background motion is the same: the small box's point is not background either way.
  ASSERT_TRUE(r.background_motion.has_value());
  EXPECT_NEAR(r.background_motion->x(), 2.0, 1e-9);
  EXPECT_EQ(r.labels[Scene::kLargeStage1], PointLabel::kDynamicStage1);
  s.prev[Scene::kSmallInside].pt -= cv::Point2f(18, 0);
  s.previous.keypoints = s.prev;
  EXPECT_EQ(RemoveDynamicPoints(s.Input(), p).labels[Scene::kSmallInside],
            PointLabel::kDynamicStage1);
  // Without a previous frame there is nothing to judge by: kept, like a large box's points.
  DynamicInput first = s.Input();
  first.previous = nullptr;
  EXPECT_EQ(RemoveDynamicPoints(first, p).labels[Scene::kSmallInside], PointLabel::kKept);
}

TEST(RemoveDynamicPointsTest, EveryBranchGetsItsLabel) {
  const Scene s;
  const DynamicResult r = RemoveDynamicPoints(s.Input(), Params());
  ASSERT_EQ(r.labels.size(), static_cast<size_t>(Scene::kCount));
  ASSERT_EQ(r.boxes.size(), 2u);
  ASSERT_TRUE(r.background_motion.has_value());
  EXPECT_EQ(r.num_background_matches, 3);
  // Mean of the three best background matches: kSmallOutside, kBg1, kBg2 (distance 0).
  EXPECT_NEAR(r.background_motion->x(), 2.0, 1e-9);
  EXPECT_NEAR(r.background_motion->y(), 1.0, 1e-9);
  const std::vector<PointLabel> expected{PointLabel::kDynamicSmallBox,
                                         PointLabel::kKept,
                                         PointLabel::kKept,
                                         PointLabel::kKept,
                                         PointLabel::kKept,
                                         PointLabel::kKept,
                                         PointLabel::kKept,
                                         PointLabel::kDynamicStage1,
                                         PointLabel::kDynamicStage2,
                                         PointLabel::kKept,
                                         PointLabel::kDynamicBoxVote,
                                         PointLabel::kKept,
                                         PointLabel::kDynamicStage2};
  for (int i = 0; i < Scene::kCount; ++i)
    EXPECT_EQ(r.labels[i], expected[i]) << "point " << i << ": " << PointLabelName(r.labels[i]);
}

TEST(RemoveDynamicPointsTest, BoxVoteOnlyForBoxesWhoseMatchedPointsMoved) {
  const Scene s;
  DynamicParams p = Params();
  // Disabled: the unmatched large-box point has no evidence of its own and is kept.
  p.box_vote_ratio = 1.5;
  EXPECT_EQ(RemoveDynamicPoints(s.Input(), p).labels[10], PointLabel::kKept);
  // The box's matched points: 3 of 6 failed a stage; a box needing more keeps its point.
  p.box_vote_ratio = 0.9;
  EXPECT_EQ(RemoveDynamicPoints(s.Input(), p).labels[10], PointLabel::kKept);
  p.box_vote_ratio = 0.3;
  p.box_vote_min_matches = 100;  // too few matched points to judge the box
  EXPECT_EQ(RemoveDynamicPoints(s.Input(), p).labels[10], PointLabel::kKept);
}

TEST(RemoveDynamicPointsTest, BoxVoteSparesTheBackgroundBehindTheMover) {
  // The large box's three failed points are at 2 m: the mover. The unmatched point, no verdict
  // of its own, at 4 m is the background seen around the mover (kept); at 2.2 m it is on the mover.
  const Scene s;
  std::vector<float> depths(Scene::kCount, 0.f);
  depths[Scene::kLargeStage1] = depths[Scene::kLargeStage2] = depths[Scene::kLargeBehind] = 2.f;
  DynamicInput in = s.Input();
  in.depths = &depths;
  const DynamicParams p = Params();
  depths[Scene::kLargeUnmatched] = 4.f;
  EXPECT_EQ(RemoveDynamicPoints(in, p).labels[Scene::kLargeUnmatched], PointLabel::kKept);
  depths[Scene::kLargeUnmatched] = 2.2f;
  EXPECT_EQ(RemoveDynamicPoints(in, p).labels[Scene::kLargeUnmatched], PointLabel::kDynamicBoxVote);
  depths[Scene::kLargeUnmatched] = 0.f;  // no depth: nothing says it is behind
  EXPECT_EQ(RemoveDynamicPoints(in, p).labels[Scene::kLargeUnmatched], PointLabel::kDynamicBoxVote);
  depths[Scene::kLargeUnmatched] = 4.f;
  DynamicParams off = p;
  off.box_vote_depth_ratio = 0.0;  // the vote as before: every point without a verdict
  EXPECT_EQ(RemoveDynamicPoints(in, off).labels[Scene::kLargeUnmatched],
            PointLabel::kDynamicBoxVote);
  depths[Scene::kLargeBehind] = 0.f;  // two failed points with depth: the mover's depth unknown
  EXPECT_EQ(RemoveDynamicPoints(in, p).labels[Scene::kLargeUnmatched], PointLabel::kDynamicBoxVote);
}

TEST(RemoveDynamicPointsTest, LargerTIncludesTheOutlierInTheBackgroundMotion) {
  const Scene s;
  DynamicParams p = Params();
  p.background_matches_t = 20;  // all 5 background matches: mean (2 * 4 + 40) / 5 = 9.6, 0.8
  const DynamicResult r = RemoveDynamicPoints(s.Input(), p);
  ASSERT_TRUE(r.background_motion.has_value());
  EXPECT_EQ(r.num_background_matches, 5);
  EXPECT_NEAR(r.background_motion->x(), 9.6, 1e-6);
  EXPECT_NEAR(r.background_motion->y(), 0.8, 1e-6);
}

TEST(RemoveDynamicPointsTest, WithoutPreviousFrameOnlySmallBoxesRemove) {
  const Scene s;
  DynamicInput in = s.Input();
  in.previous = nullptr;
  const DynamicResult r = RemoveDynamicPoints(in, Params());
  for (int i = 0; i < Scene::kCount; ++i)
    EXPECT_EQ(r.labels[i],
              i == Scene::kSmallInside ? PointLabel::kDynamicSmallBox : PointLabel::kKept);
  EXPECT_FALSE(r.background_motion.has_value());
}

TEST(RemoveDynamicPointsTest, WithoutPredictionOnlyStageOneRuns) {
  const Scene s;
  DynamicInput in = s.Input();
  in.predicted_cam_from_world.reset();
  const DynamicResult r = RemoveDynamicPoints(in, Params());
  EXPECT_EQ(r.labels[Scene::kLargeStage1], PointLabel::kDynamicStage1);
  EXPECT_EQ(r.labels[Scene::kLargeStage2], PointLabel::kKept);
  EXPECT_EQ(r.labels[Scene::kLargeBehind], PointLabel::kKept);
}

TEST(RemoveDynamicPointsTest, InactivePointsAreLeftAlone) {
  const Scene s;
  DynamicInput in = s.Input();
  in.active.assign(Scene::kCount, true);
  in.active[Scene::kSmallInside] = false;
  in.active[Scene::kLargeStage1] = false;
  const DynamicResult r = RemoveDynamicPoints(in, Params());
  EXPECT_EQ(r.labels[Scene::kSmallInside], PointLabel::kKept);
  EXPECT_EQ(r.labels[Scene::kLargeStage1], PointLabel::kKept);
  EXPECT_EQ(r.labels[Scene::kLargeStage2], PointLabel::kDynamicStage2);
}

// Forward motion (the street case): the camera moves 0.5 m ahead between frames. Static points
// then flow outwards by an amount that grows with image position and inverse depth, so a parked
// car's near points differ from the background's mean displacement by far more than D_dis.
struct ForwardScene {
  Camera camera = TestCamera();
  // One large box (car class) on the right half of the image.
  std::vector<Detection> detections{Det(2, 400, 150, 220, 300)};
  std::vector<cv::KeyPoint> cur, prev;
  cv::Mat cur_desc, prev_desc;
  std::vector<float> cur_depths;
  PreviousFrameFeatures previous;
  Rigid3d cur_from_prev = Rigid3d::Identity();

  enum : int {
    kParked1 = 0,        // static, 4 m away, in the box: prev depth known
    kParked2,            // static, 5 m
    kParkedNoPrevDepth,  // static, 4.5 m, depth known only in the current frame
    kMoving,             // the 3D point moved 0.4 m sideways: prev depth known
    kMovingNoPrevDepth,  // moved 0.4 m sideways, depth known only in the current frame
    kNoDepth,            // static, depth unknown in both frames: no verdict
    kBoxCount
  };

  ForwardScene() {
    cur_from_prev.translation() = Eigen::Vector3d(0, 0, -0.5);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const Eigen::Vector3d no_point(nan, nan, nan);
    auto add = [&](const Eigen::Vector3d& prev_cam, const Eigen::Vector3d& motion, bool prev_depth,
                   bool cur_depth) {
      const Eigen::Vector3d cur_cam = cur_from_prev * (prev_cam + motion);
      const Eigen::Vector2d p = camera.Project(prev_cam), c = camera.Project(cur_cam);
      prev.push_back(Kp(static_cast<float>(p.x()), static_cast<float>(p.y())));
      cur.push_back(Kp(static_cast<float>(c.x()), static_cast<float>(c.y())));
      previous.points_cam.push_back(prev_depth ? prev_cam : no_point);
      cur_depths.push_back(cur_depth ? static_cast<float>(cur_cam.z()) : -1.f);
    };
    const Eigen::Vector3d still = Eigen::Vector3d::Zero(), sideways(0.4, 0, 0);
    auto at = [&](double u, double v, double z) {
      return camera.Unproject(Eigen::Vector2d(u, v), z);
    };
    add(at(520, 300, 4), still, true, true);
    add(at(580, 250, 5), still, true, true);
    add(at(480, 380, 4.5), still, false, true);
    add(at(470, 260, 6), sideways, true, true);
    add(at(540, 340, 6), sideways, false, true);
    add(at(450, 220, 7), still, false, false);
    // Background: a grid of static points at 3-20 m on the left of the image, outside the box.
    for (int k = 0; k < 24; ++k) {
      const double u = 30 + 60 * (k % 6), v = 40 + 110 * (k / 6);
      add(at(u, v, 3.0 + 17.0 * ((k * 7) % 24) / 23.0), still, true, k % 3 != 0);
    }
    cur_desc = RandomDescriptors(static_cast<int>(cur.size()), 11);
    prev_desc = cur_desc.clone();
    previous.keypoints = prev;
    previous.descriptors = prev_desc;
  }

  DynamicInput Input() const {
    DynamicInput in = MakeInput(cur, cur_desc, detections, previous, camera);
    in.depths = &cur_depths;
    return in;  // no constant-velocity prediction: stage 2 does not run
  }
};

DynamicParams ForwardParams() {
  DynamicParams p;
  p.box_vote_ratio = 2.0;  // judge every point on its own evidence
  return p;
}

TEST(FitBackgroundMotionTest, RecoversTheCameraMotionFromTheBackground) {
  const ForwardScene s;
  std::vector<cv::DMatch> matches;
  std::vector<char> in_box(s.cur.size(), 0);
  for (size_t i = 0; i < s.cur.size(); ++i) {
    matches.emplace_back(static_cast<int>(i), static_cast<int>(i), 0.f);
    in_box[i] = i < ForwardScene::kBoxCount;  // the moving points must not take part
  }
  int inliers = 0;
  const std::optional<Rigid3d> fit =
      FitBackgroundMotion(s.cur, s.previous, matches, in_box, s.camera, ForwardParams(), &inliers);
  ASSERT_TRUE(fit.has_value());
  EXPECT_EQ(inliers, 24);
  EXPECT_LT((fit->translation() - s.cur_from_prev.translation()).norm(), 1e-4);
  EXPECT_LT((fit->linear() - Eigen::Matrix3d::Identity()).norm(), 1e-4);
  // Too few background points with depth: no fit.
  DynamicParams p = ForwardParams();
  p.motion_min_inliers = 25;
  EXPECT_FALSE(FitBackgroundMotion(s.cur, s.previous, matches, in_box, s.camera, p).has_value());
}

TEST(RemoveDynamicPointsTest, MotionCompensationKeepsStaticObjectsUnderForwardMotion) {
  const ForwardScene s;
  const DynamicResult r = RemoveDynamicPoints(s.Input(), ForwardParams());
  EXPECT_TRUE(r.motion_compensated);
  EXPECT_EQ(r.num_motion_inliers, 24);
  ASSERT_TRUE(r.background_motion.has_value());
  EXPECT_LT(r.background_motion->norm(), 1e-3);  // the fit explains the background exactly
  EXPECT_EQ(r.labels[ForwardScene::kParked1], PointLabel::kKept);
  EXPECT_EQ(r.labels[ForwardScene::kParked2], PointLabel::kKept);
  EXPECT_EQ(r.labels[ForwardScene::kParkedNoPrevDepth], PointLabel::kKept);  // checked backwards
  EXPECT_EQ(r.labels[ForwardScene::kMoving], PointLabel::kDynamicStage1);
  EXPECT_EQ(r.labels[ForwardScene::kMovingNoPrevDepth], PointLabel::kDynamicStage1);
  EXPECT_EQ(r.labels[ForwardScene::kNoDepth], PointLabel::kKept);  // no evidence either way
  for (size_t i = ForwardScene::kBoxCount; i < s.cur.size(); ++i)
    EXPECT_EQ(r.labels[i], PointLabel::kKept);
}

TEST(RemoveDynamicPointsTest, PaperStageOneJudgesParkedCarsMovingUnderForwardMotion) {
  // The paper's single mean displacement: the near static points flow far more than the
  // background's mean and are removed; this is why compensation is the default.
  const ForwardScene s;
  DynamicParams p = ForwardParams();
  p.stage1_motion_compensation = false;
  const DynamicResult r = RemoveDynamicPoints(s.Input(), p);
  EXPECT_FALSE(r.motion_compensated);
  EXPECT_EQ(r.labels[ForwardScene::kParked1], PointLabel::kDynamicStage1);
  EXPECT_EQ(r.labels[ForwardScene::kParked2], PointLabel::kDynamicStage1);
  EXPECT_EQ(r.labels[ForwardScene::kParkedNoPrevDepth], PointLabel::kDynamicStage1);
}

TEST(RemoveDynamicPointsTest, UnjudgedPointsFollowTheBoxVote) {
  // With the vote on, the box's judged points: 2 of 5 moved (40 %): the point without depth in
  // either frame (no verdict of its own) goes with its box.
  const ForwardScene s;
  DynamicParams p = ForwardParams();
  p.box_vote_ratio = 0.3;
  p.box_vote_min_matches = 5;
  EXPECT_EQ(RemoveDynamicPoints(s.Input(), p).labels[ForwardScene::kNoDepth],
            PointLabel::kDynamicBoxVote);
  p.box_vote_ratio = 0.5;
  EXPECT_EQ(RemoveDynamicPoints(s.Input(), p).labels[ForwardScene::kNoDepth], PointLabel::kKept);
}

TEST(RemoveDynamicPointsTest, WithoutBackgroundDepthStageOneFallsBackToThePaperTest) {
  ForwardScene s;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (size_t i = ForwardScene::kBoxCount; i < s.cur.size(); ++i)
    s.previous.points_cam[i] = Eigen::Vector3d(nan, nan, nan);
  const DynamicResult r = RemoveDynamicPoints(s.Input(), ForwardParams());
  EXPECT_FALSE(r.motion_compensated);
  EXPECT_EQ(r.labels[ForwardScene::kParked1], PointLabel::kDynamicStage1);
}

// The epipolar test needs no depth: every depth of the forward scene removed, the previous frame
// at the origin and this frame's prediction off the true motion by 0.5 degrees of yaw and a
// translation 5 degrees off its direction (the refinement on the background takes both out).
struct EpipolarForwardScene : ForwardScene {
  EpipolarForwardScene() {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (auto& x : previous.points_cam) x = Eigen::Vector3d(nan, nan, nan);
    for (float& z : cur_depths) z = -1.f;
    previous.cam_from_world = Rigid3d::Identity();
    prediction = cur_from_prev;
    prediction.linear() = ExpSO3(Eigen::Vector3d(0, 0.5 * M_PI / 180, 0));
    prediction.translation() =
        Eigen::Vector3d(0.5 * std::sin(5 * M_PI / 180), 0, -0.5 * std::cos(5 * M_PI / 180));
  }
  DynamicInput Input() const {
    DynamicInput in = ForwardScene::Input();
    in.predicted_cam_from_world = prediction;
    return in;
  }
  std::vector<Eigen::Vector2d> Background(bool current) const {
    std::vector<Eigen::Vector2d> px;
    for (size_t i = kBoxCount; i < cur.size(); ++i) {
      const cv::Point2f& p = current ? cur[i].pt : prev[i].pt;
      px.emplace_back(p.x, p.y);
    }
    return px;
  }
  Rigid3d prediction = Rigid3d::Identity();
};

DynamicParams EpipolarParams() {
  DynamicParams p = ForwardParams();
  p.dynamic_test = "epipolar";
  return p;
}

TEST(EpipolarTest, DistanceFromTheLineOfTheMotionsFundamentalMatrix) {
  const Camera camera = TestCamera();
  Rigid3d cur_from_prev = Rigid3d::Identity();
  cur_from_prev.translation() = Eigen::Vector3d(-0.3, 0, 0);  // sideways: horizontal lines
  const Eigen::Matrix3d f = FundamentalFromMotion(cur_from_prev, camera);
  const Eigen::Vector3d x = camera.Unproject(Eigen::Vector2d(100, 200), 4.0);
  const Eigen::Vector2d a = camera.Project(x), b = camera.Project(cur_from_prev * x);
  EXPECT_NEAR(EpipolarDistance(f, a, b), 0.0, 1e-9);
  EXPECT_NEAR(EpipolarDistance(f, a, b + Eigen::Vector2d(0, 3)), 3.0, 1e-9);
  EXPECT_NEAR(EpipolarDistance(f, a, b + Eigen::Vector2d(40, 0)), 0.0, 1e-9);  // along the line
  // The translation's length does not matter.
  cur_from_prev.translation() *= 7;
  EXPECT_NEAR(
      EpipolarDistance(FundamentalFromMotion(cur_from_prev, camera), a, b + Eigen::Vector2d(0, 3)),
      3.0, 1e-9);
}

TEST(EpipolarTest, TheMotionIsRefinedOnTheBackground) {
  const EpipolarForwardScene s;
  const Rigid3d refined = RefineMotionOnBackground(s.prediction, s.Background(false),
                                                   s.Background(true), s.camera, 2.0);
  EXPECT_LT((refined.linear() - s.cur_from_prev.linear()).norm(), 1e-6);
  EXPECT_LT(
      (refined.translation().normalized() - s.cur_from_prev.translation().normalized()).norm(),
      1e-6);
  EXPECT_NEAR(refined.translation().norm(), s.prediction.translation().norm(), 1e-12);
  // Too few points: the prediction comes back unchanged.
  const std::vector<Eigen::Vector2d> few(7, Eigen::Vector2d(1, 1));
  EXPECT_TRUE(
      RefineMotionOnBackground(s.prediction, few, few, s.camera, 2.0).isApprox(s.prediction, 0.0));
}

TEST(RemoveDynamicPointsTest, TheEpipolarTestKeepsParkedCarsWithoutAnyDepth) {
  const EpipolarForwardScene s;
  const DynamicResult r = RemoveDynamicPoints(s.Input(), EpipolarParams());
  EXPECT_TRUE(r.epipolar_fitted);
  EXPECT_FALSE(r.background_motion.has_value());  // the depth test did not run
  EXPECT_EQ(r.labels[ForwardScene::kParked1], PointLabel::kKept);
  EXPECT_EQ(r.labels[ForwardScene::kParked2], PointLabel::kKept);
  EXPECT_EQ(r.labels[ForwardScene::kParkedNoPrevDepth], PointLabel::kKept);
  EXPECT_EQ(r.labels[ForwardScene::kNoDepth], PointLabel::kKept);
  // Both movers leave their epipolar lines (by 4.8 and 15 px).
  EXPECT_EQ(r.labels[ForwardScene::kMoving], PointLabel::kDynamicStage1);
  EXPECT_EQ(r.labels[ForwardScene::kMovingNoPrevDepth], PointLabel::kDynamicStage1);
  for (size_t i = ForwardScene::kBoxCount; i < s.cur.size(); ++i)
    EXPECT_EQ(r.labels[i], PointLabel::kKept);
  // The unrefined prediction would have judged the parked car moving: the refinement matters.
  EpipolarForwardScene unrefined = s;
  unrefined.previous.cam_from_world.reset();  // no motion: the fundamental matrix is fitted
  const DynamicResult fitted = RemoveDynamicPoints(unrefined.Input(), EpipolarParams());
  EXPECT_TRUE(fitted.epipolar_fitted);
  EXPECT_EQ(fitted.num_motion_inliers, 24);
  const Eigen::Matrix3d predicted = FundamentalFromMotion(s.prediction, s.camera);
  const cv::Point2f a = s.prev[ForwardScene::kParked1].pt, b = s.cur[ForwardScene::kParked1].pt;
  EXPECT_GT(EpipolarDistance(predicted, Eigen::Vector2d(a.x, a.y), Eigen::Vector2d(b.x, b.y)), 2.0);
}

TEST(RemoveDynamicPointsTest, TheEpipolarBoxVoteWeighsTheBackgroundsOwnFailures) {
  // 2 of the box's 5 judged points failed (40 %, above box_vote_ratio 0.3): with a clean
  // background the box moves and its unjudged point goes with it. With a quarter of the
  // background mismatched, 2 of 5 is what a static box shows too, and the point stays.
  EpipolarForwardScene s;
  DynamicParams p = EpipolarParams();
  p.box_vote_ratio = 0.3;
  p.box_vote_min_matches = 5;
  s.previous.keypoints[ForwardScene::kNoDepth] = cv::KeyPoint();  // unmatched: no verdict
  s.previous.descriptors.row(ForwardScene::kNoDepth).setTo(0);
  s.cur_desc.row(ForwardScene::kNoDepth).setTo(255);
  EXPECT_EQ(RemoveDynamicPoints(s.Input(), p).labels[ForwardScene::kNoDepth],
            PointLabel::kDynamicBoxVote);
  // Six background points matched to the wrong previous keypoint (30 px to the side).
  for (size_t i = ForwardScene::kBoxCount; i < ForwardScene::kBoxCount + 6; ++i)
    s.previous.keypoints[i].pt.x += 30;
  EXPECT_EQ(RemoveDynamicPoints(s.Input(), p).labels[ForwardScene::kNoDepth], PointLabel::kKept);
}

TEST(RemoveDynamicPointsTest, NoDetectionsKeepsEverythingAndBadInputThrows) {
  Scene s;
  s.detections.clear();
  const DynamicResult r = RemoveDynamicPoints(s.Input(), Params());
  for (PointLabel l : r.labels) EXPECT_EQ(l, PointLabel::kKept);
  Scene t;
  t.previous.points_world.resize(2);
  EXPECT_THROW(RemoveDynamicPoints(t.Input(), Params()), std::invalid_argument);
  DynamicInput in = t.Input();
  in.camera = nullptr;
  EXPECT_THROW(RemoveDynamicPoints(in, Params()), std::invalid_argument);
  Scene u;
  u.previous.points_cam.resize(3);
  EXPECT_THROW(RemoveDynamicPoints(u.Input(), Params()), std::invalid_argument);
  ForwardScene f;
  f.cur_depths.pop_back();
  EXPECT_THROW(RemoveDynamicPoints(f.Input(), ForwardParams()), std::invalid_argument);
}

}  // namespace
}  // namespace ademono
