// Scoring of keypoint labels against a synthetic sequence's moving-object mask.
#include "ademono/runner/synthetic_truth.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "ademono/core/error.h"
#include "runner_test_util.h"

namespace fs = std::filesystem;

namespace ademono {
namespace {

TEST(SyntheticTruthTest, ScoresLabelsAgainstTheMaskAndTheStaticPersonBox) {
  const fs::path dir = runner_test::TempDir("truth");
  fs::create_directories(dir / "masks");
  cv::Mat mask(100, 200, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(0, 0, 50, 100)).setTo(255);  // a moving object on the left
  cv::imwrite((dir / "masks" / "f0.png").string(), mask);
  const SyntheticTruth truth(dir);
  ASSERT_TRUE(truth.Available());
  FrameData frame;
  frame.name = "f0";
  frame.image = cv::Mat(100, 200, CV_8UC3, cv::Scalar::all(0));
  Detection moving, standing;
  moving.class_id = standing.class_id = 0;
  moving.box = cv::Rect2f(0, 0, 50, 100);
  standing.box = cv::Rect2f(120, 10, 40, 80);  // no moving pixels: the static person
  Detection parked;  // a static car; a chair box (class 56) is not a dynamic class
  parked.class_id = 2;
  parked.box = cv::Rect2f(60, 60, 30, 30);
  Detection chair;
  chair.class_id = 56;
  chair.box = cv::Rect2f(170, 10, 20, 20);
  const std::vector<cv::KeyPoint> kps{{10, 10, 7},  {20, 50, 7},  {30, 80, 7},
                                      {130, 20, 7}, {140, 50, 7}, {90, 50, 7},
                                      {70, 70, 7},  {80, 75, 7},  {175, 15, 7}};
  const std::vector<PointLabel> labels{PointLabel::kDynamicStage1,
                                       PointLabel::kKept,
                                       PointLabel::kEnhancementDropped,
                                       PointLabel::kKept,
                                       PointLabel::kDynamicBoxVote,
                                       PointLabel::kKept,
                                       PointLabel::kDynamicSmallBox,
                                       PointLabel::kKept,
                                       PointLabel::kKept};
  TruthCounts counts;
  truth.Score(frame, {moving, standing, parked, chair}, kps, labels, &counts);
  EXPECT_EQ(counts.moving_keypoints, 2);  // the enhancement-dropped one does not count
  EXPECT_EQ(counts.moving_removed, 1);
  EXPECT_EQ(counts.moving_kept, 1);
  EXPECT_EQ(counts.static_person_keypoints, 2);
  EXPECT_EQ(counts.static_person_removed, 1);
  // Static points in dynamic-class boxes: the static person's two and the parked car's two.
  EXPECT_EQ(counts.static_in_box_keypoints, 4);
  EXPECT_EQ(counts.static_in_box_removed, 2);
  // Every judged keypoint off the mask is static (6), two of them removed; the moving ones are
  // all inside the detector's person box, so none is unboxed.
  EXPECT_EQ(counts.static_keypoints, 6);
  EXPECT_EQ(counts.static_removed, 2);
  EXPECT_EQ(counts.moving_unboxed_keypoints, 0);
  // Without the moving person's box, its judged keypoints are movers the detector missed.
  TruthCounts unboxed;
  truth.Score(frame, {standing, parked, chair}, kps, labels, &unboxed);
  EXPECT_EQ(unboxed.moving_unboxed_keypoints, 2);
  EXPECT_EQ(unboxed.moving_unboxed_removed, 1);
  // The geometric test keeping the moving keypoint 1 (labelled kept; judged moving) and the
  // static keypoint 5 (unconfirmed) out of the pose counts as removing them; a pose inlier or
  // outlier does not.
  using M = MatchState;
  const std::vector<MatchState> states{M::kUnmatched,   M::kJudgedMoving, M::kUnmatched,
                                       M::kPoseInlier,  M::kUnmatched,    M::kUnconfirmed,
                                       M::kUnmatched,   M::kPoseOutlier,  M::kPoseInlier};
  TruthCounts geometric;
  truth.Score(frame, {standing, parked, chair}, kps, labels, &geometric, &states);
  EXPECT_EQ(geometric.moving_removed, 2);
  EXPECT_EQ(geometric.moving_unboxed_removed, 2);
  EXPECT_EQ(geometric.moving_not_removed_unboxed, 0);
  EXPECT_EQ(geometric.static_removed, unboxed.static_removed + 1);
  // What removed them: the box filter's labels first, the geometric test only where none.
  EXPECT_EQ(geometric.static_removed_box_vote, 1);
  EXPECT_EQ(geometric.static_removed_small_box, 1);
  EXPECT_EQ(geometric.static_removed_stage1, 0);
  EXPECT_EQ(geometric.static_removed_unconfirmed, 1);
  EXPECT_EQ(geometric.static_removed_judged_moving, 0);
  EXPECT_EQ(geometric.moving_removed_geometric, 1);
  // The kept keypoints by state: static 3 (inlier), 5 (unconfirmed), 7 (outlier), 8 (inlier).
  EXPECT_EQ(geometric.static_kept_by_state, (TruthCounts::StateCounts{0, 2, 1, 1, 0}));
  EXPECT_EQ(geometric.moving_kept_by_state, (TruthCounts::StateCounts{0, 0, 0, 0, 1}));
  EXPECT_EQ(geometric.static_at_mover_edge_keypoints, 0);
  // A corner just outside the mover's outline (x = 51, 2 px from its last pixel) is static but
  // at the mover's edge; 3 px away it is not.
  TruthCounts edge;
  truth.Score(frame, {}, {{51, 50, 7}, {53, 50, 7}},
              {PointLabel::kDynamicStage1, PointLabel::kKept}, &edge);
  EXPECT_EQ(edge.static_keypoints, 2);
  EXPECT_EQ(edge.static_at_mover_edge_keypoints, 1);
  EXPECT_EQ(edge.static_at_mover_edge_removed, 1);
  EXPECT_EQ(edge.static_removed_stage1, 1);

  // Whether a keypoint entered tracking or the map: a moving pose inlier entered; a new
  // keyframe point made from a keypoint entered only if it was ever admitted, also through the
  // point that replaced it (fusion). Static: a new point judged moving before it was admitted is
  // kept out (removed); one never admitted without such a verdict is only unconfirmed.
  auto point = [](bool admitted, int motion_verdicts) {
    auto p = std::make_shared<MapPoint>(0, Eigen::Vector3d::Zero(), nullptr, 0);
    p->admitted = admitted;
    p->motion_verdicts = motion_verdicts;
    return p;
  };
  const auto replaced = point(false, 0);
  replaced->replaced_by = point(true, 0);
  // Keypoint 1 (moving, kept): a pose inlier. Keypoint 0 (moving, labelled) made a new point
  // that was admitted all the same (it entered the map). Static 5 (unconfirmed) made one judged
  // moving (already removed: counted once), static 8 one never judged, static 7 one replaced by
  // an admitted point, static 3 one judged moving.
  const std::vector<MatchState> fate{M::kUnmatched,  M::kPoseInlier, M::kUnmatched,
                                     M::kPoseInlier, M::kUnmatched,  M::kUnconfirmed,
                                     M::kUnmatched,  M::kUnmatched,  M::kUnmatched};
  const std::vector<std::pair<size_t, std::shared_ptr<const MapPoint>>> created{
      {0, point(true, 0)}, {5, point(false, 2)}, {8, point(false, 0)}, {7, replaced},
      {3, point(false, 1)}};
  TruthCounts entered;
  std::vector<PendingPoint> pending;
  truth.Score(frame, {}, kps, labels, &entered, &fate, &created, &pending);
  EXPECT_EQ(pending.size(), 5u);
  EXPECT_EQ(entered.moving_pose_inliers, 1);
  EXPECT_EQ(entered.moving_new_points, 1);
  EXPECT_EQ(entered.static_new_points, 4);
  const long long removed_before = entered.static_kept_out;
  EXPECT_EQ(removed_before, entered.static_removed);
  SyntheticTruth::Resolve(pending, &entered);
  EXPECT_EQ(entered.moving_new_points_admitted, 1);
  EXPECT_EQ(entered.MovingEntered(), 2);  // both moving keypoints entered
  EXPECT_EQ(entered.static_new_points_judged_out, 2);
  EXPECT_EQ(entered.static_new_points_unconfirmed, 1);
  EXPECT_EQ(entered.static_kept_out, removed_before + 1);  // keypoint 3; 5 was already removed
  EXPECT_EQ(entered.ToJson()["moving_kept_out"], 0);

  frame.name = "missing";
  EXPECT_THROW(truth.Score(frame, {}, kps, labels, &counts), InputError);
  EXPECT_FALSE(SyntheticTruth(dir / "nothing").Available());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ademono
