// The geometric test for movers without a box (slam/static_probability.h): the verdict of one
// observation, the Bayes update, and on the synthetic office with no boxes at all (the walking
// persons are movers no detector reports) the map points on them are judged moving while the
// static scene is kept.
#include "ademono/slam/static_probability.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "ademono/slam/system.h"
#include "synthetic_sequence.h"

namespace ademono {
namespace {

using testing_util::SyntheticOffice;

TEST(StaticProbabilityTest, JudgesResidualAndDepth) {
  const StaticTestParams p;
  EXPECT_EQ(JudgeObservation(1.0, std::nullopt, p), StaticEvidence::kStatic);
  EXPECT_EQ(JudgeObservation(1.0, 0.01, p), StaticEvidence::kStatic);
  // Depth disagreement alone is motion (a walker coming towards the camera along the ray).
  EXPECT_EQ(JudgeObservation(1.0, 0.3, p), StaticEvidence::kDynamic);
  EXPECT_EQ(JudgeObservation(10.0, std::nullopt, p), StaticEvidence::kDynamic);
  // Between the bands: no verdict.
  EXPECT_EQ(JudgeObservation(4.0, 0.01, p), StaticEvidence::kNone);
  EXPECT_EQ(JudgeObservation(1.0, 0.1, p), StaticEvidence::kNone);
  // Behind the camera / no projection.
  EXPECT_EQ(JudgeObservation(std::numeric_limits<double>::infinity(), std::nullopt, p),
            StaticEvidence::kDynamic);
}

TEST(StaticProbabilityTest, DepthWithAnErrorModelIsJudgedAgainstItsSigma) {
  StaticTestParams p;
  p.depth_sigmas = 0.5;
  p.depth_dynamic_sigmas = 1.0;
  // A network depth with sigma_z / z = 0.4: 30 % disagreement is motion for a sensor but within
  // the network's error (static band 0.2, dynamic band 0.4) it is no verdict ...
  EXPECT_EQ(JudgeObservation(1.0, 0.3, p), StaticEvidence::kDynamic);
  EXPECT_EQ(JudgeObservation(1.0, 0.3, p, 0.4), StaticEvidence::kNone);
  EXPECT_EQ(JudgeObservation(1.0, 0.15, p, 0.4), StaticEvidence::kStatic);
  // ... while a disagreement beyond it is still motion, and the reprojection residual decides as
  // before.
  EXPECT_EQ(JudgeObservation(1.0, 0.5, p, 0.4), StaticEvidence::kDynamic);
  EXPECT_EQ(JudgeObservation(10.0, 0.01, p, 0.4), StaticEvidence::kDynamic);
  // A small sigma never narrows the sensor bands.
  EXPECT_EQ(JudgeObservation(1.0, 0.04, p, 0.01), StaticEvidence::kStatic);
  EXPECT_EQ(JudgeObservation(1.0, 0.1, p, 0.01), StaticEvidence::kNone);
}

TEST(StaticProbabilityTest, ParallaxShiftIsTheDepthBandSeenFromElsewhere) {
  const Eigen::Vector3d point(0, 0, 10);
  const Rigid3d cam_from_world = Rigid3d::Identity();
  // Seen from the camera that measured it, a depth error moves the point along the line of
  // sight: no shift in the image.
  EXPECT_NEAR(ParallaxShiftPx(point, Eigen::Vector3d::Zero(), cam_from_world, 500, 500, 0.05), 0,
              1e-9);
  // Measured from 2 m to the left: the ray is (2, 0, 10); 5 % of it is (0.1, 0, 0.5). Nearer,
  // the point projects at x/z = -0.1 / 9.5, farther at 0.1 / 10.5: the larger shift counts.
  EXPECT_NEAR(ParallaxShiftPx(point, Eigen::Vector3d(-2, 0, 0), cam_from_world, 500, 500, 0.05),
              500 * 0.1 / 9.5, 1e-9);
  // Twice the band, about twice the shift; a nearer point, a larger shift for the same baseline.
  EXPECT_NEAR(ParallaxShiftPx(point, Eigen::Vector3d(-2, 0, 0), cam_from_world, 500, 500, 0.1),
              500 * 0.2 / 9.0, 1e-9);
  EXPECT_GT(ParallaxShiftPx(Eigen::Vector3d(0, 0, 5), Eigen::Vector3d(-2, 0, 0), cam_from_world,
                            500, 500, 0.05),
            500 * 0.1 / 9.5);
  // A shifted point behind the camera: no finite shift.
  EXPECT_TRUE(std::isinf(ParallaxShiftPx(Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d(0, 0, -20),
                                         cam_from_world, 500, 500, 0.05)));
}

TEST(StaticProbabilityTest, DepthIsJudgedAtTheDistanceItWasMeasuredAt) {
  StaticTestParams p;
  // Made from a depth taken 30 m away, with 5 % of error that is 1.5 m; seen now at 20 m, the
  // map says 21.5 m: 7.5 % of the depth measured now, but 5 % of where it was measured.
  EXPECT_NEAR(RelativeDepthDisagreement(21.5, 20.0, 30.0, p), 1.5 / 30.0, 1e-12);
  EXPECT_EQ(JudgeObservation(1.0, RelativeDepthDisagreement(21.5, 20.0, 30.0, p), p),
            StaticEvidence::kStatic);
  // Seen from farther than it was made (or the reference unknown): the measured depth, as before.
  EXPECT_NEAR(RelativeDepthDisagreement(21.5, 20.0, 10.0, p), 1.5 / 20.0, 1e-12);
  EXPECT_NEAR(RelativeDepthDisagreement(21.5, 20.0, 0.0, p), 1.5 / 20.0, 1e-12);
  // Switched off: the measured depth always.
  p.depth_at_reference = false;
  EXPECT_NEAR(RelativeDepthDisagreement(21.5, 20.0, 30.0, p), 1.5 / 20.0, 1e-12);
  EXPECT_EQ(JudgeObservation(1.0, RelativeDepthDisagreement(21.5, 20.0, 30.0, p), p),
            StaticEvidence::kNone);
}

TEST(StaticProbabilityTest, PointDepthSigmaIsTheConfiguredNoiseOrTheErrorModel) {
  StaticTestParams p;
  // A sensor by default: no sigma, so no allowance (fixed pixel thresholds).
  EXPECT_EQ(PointDepthSigma(20.0, p), 0.0);
  // The street's simulated network: 1 % + 0.1 %/m, 3 % at 20 m.
  p.point_sigma_relative = 0.01;
  p.point_sigma_per_metre = 0.001;
  EXPECT_NEAR(PointDepthSigma(20.0, p), 0.03, 1e-12);
  // A depth error model that is wider wins; a narrower one does not narrow it.
  EXPECT_NEAR(PointDepthSigma(20.0, p, 0.2), 0.2, 1e-12);
  EXPECT_NEAR(PointDepthSigma(20.0, p, 0.01), 0.03, 1e-12);
}

// Two depths with the street's simulated network noise (1 % + 0.1 %/m each) disagree by more than
// the fixed 5 % band often beyond ~25 m; the bands widen to 2 and 4 of their combined sigma.
TEST(StaticProbabilityTest, DepthBandsWidenWithTheConfiguredPointSigma) {
  StaticTestParams p;
  // No sigma configured (a sensor): nothing widens.
  EXPECT_EQ(PointDepthDisagreementSigma(30.0, 30.0, p), 0.0);
  p.point_sigma_relative = 0.01;
  p.point_sigma_per_metre = 0.001;
  // Both at 30 m: 4 % each, sqrt(2) x 4 % combined.
  EXPECT_NEAR(PointDepthDisagreementSigma(30.0, 30.0, p), std::sqrt(2.0) * 0.04, 1e-12);
  // Made at 40 m (5 %, 2 m), seen at 20 m (3 %, 0.6 m): relative to the reference distance.
  EXPECT_NEAR(PointDepthDisagreementSigma(20.0, 40.0, p), std::hypot(2.0, 0.6) / 40.0, 1e-12);
  // Reference unknown: the measured depth for both.
  EXPECT_NEAR(PointDepthDisagreementSigma(20.0, 0.0, p), std::sqrt(2.0) * 0.03, 1e-12);
  EXPECT_EQ(PointDepthDisagreementSigma(0.0, 30.0, p), 0.0);
  const double sigma = PointDepthDisagreementSigma(30.0, 30.0, p);  // 5.7 %
  // 8 % disagreement: no verdict at the fixed bands, static within 2 sigmas (11.3 %).
  EXPECT_EQ(JudgeObservation(1.0, 0.08, p), StaticEvidence::kNone);
  EXPECT_EQ(JudgeObservation(1.0, 0.08, p, 0.0, 0.0, sigma), StaticEvidence::kStatic);
  // 18 %: motion at the fixed bands, no verdict within 4 sigmas (22.6 %), motion beyond.
  EXPECT_EQ(JudgeObservation(1.0, 0.18, p), StaticEvidence::kDynamic);
  EXPECT_EQ(JudgeObservation(1.0, 0.18, p, 0.0, 0.0, sigma), StaticEvidence::kNone);
  EXPECT_EQ(JudgeObservation(1.0, 0.25, p, 0.0, 0.0, sigma), StaticEvidence::kDynamic);
  // A small sigma never narrows the fixed bands; the residual decides as before.
  EXPECT_EQ(JudgeObservation(1.0, 0.04, p, 0.0, 0.0, 0.001), StaticEvidence::kStatic);
  EXPECT_EQ(JudgeObservation(10.0, 0.01, p, 0.0, 0.0, sigma), StaticEvidence::kDynamic);
}

TEST(StaticProbabilityTest, ResidualAllowanceWidensBothResidualBands) {
  const StaticTestParams p;  // 2.5 px static, 6 px motion
  EXPECT_EQ(JudgeObservation(8.0, 0.01, p), StaticEvidence::kDynamic);
  EXPECT_EQ(JudgeObservation(8.0, 0.01, p, 0.0, 3.0), StaticEvidence::kNone);     // 8 <= 9
  EXPECT_EQ(JudgeObservation(8.0, 0.01, p, 0.0, 6.0), StaticEvidence::kStatic);   // 8 <= 8.5
  // The allowance is about the point's position, not its depth: depth motion stays motion.
  EXPECT_EQ(JudgeObservation(1.0, 0.3, p, 0.0, 6.0), StaticEvidence::kDynamic);
  // Nothing to allow (negative or not finite): the fixed bands.
  EXPECT_EQ(JudgeObservation(8.0, 0.01, p, 0.0, -3.0), StaticEvidence::kDynamic);
  EXPECT_EQ(JudgeObservation(8.0, 0.01, p, 0.0, std::numeric_limits<double>::infinity()),
            StaticEvidence::kDynamic);
}

TEST(StaticProbabilityTest, MotionOutweighsAgreementAndStaysReversible) {
  double p = 0.45;
  p = UpdateStaticProbability(p, StaticEvidence::kStatic);
  EXPECT_NEAR(p, 0.45 * 1.5 / (0.45 * 1.5 + 0.55), 1e-12);
  EXPECT_GE(p, 0.5);  // one agreeing frame admits a new point
  p = UpdateStaticProbability(p, StaticEvidence::kDynamic);
  EXPECT_LT(p, 0.5);  // one moving frame removes it again
  EXPECT_EQ(UpdateStaticProbability(0.3, StaticEvidence::kNone), 0.3);
  // Clamped: a long history can still be overturned.
  double high = 0.5;
  for (int i = 0; i < 100; ++i) high = UpdateStaticProbability(high, StaticEvidence::kStatic);
  EXPECT_DOUBLE_EQ(high, 0.98);
  for (int i = 0; i < 4; ++i) high = UpdateStaticProbability(high, StaticEvidence::kDynamic);
  EXPECT_LT(high, 0.5);
}

struct BoxlessRun {
  double ate_rmse = 0;
  int tracked = 0;
  long long judged_dynamic = 0;
};

// The office with its walking persons, tracked with no detections at all.
BoxlessRun TrackWithoutBoxes(const SyntheticOffice& sequence, bool static_test) {
  SystemOptions options;
  options.tracking.static_test = static_test;
  System system(sequence.GetCamera(), options);
  BoxlessRun run;
  for (size_t i = 0; i < sequence.Size(); ++i) {
    const FrameData frame = sequence.Load(i);
    const TrackResult r = system.TrackFrame(frame, frame.depth, {});
    run.tracked += r.tracked;
    run.judged_dynamic += r.geometric_dynamic;
  }
  system.Shutdown();
  const Rigid3d first_from_world = sequence.WorldFromCam(0).inverse();
  double sum2 = 0;
  const Trajectory trajectory = system.FrameTrajectory();
  for (const StampedPose& p : trajectory) {
    const size_t i = static_cast<size_t>(std::lround(p.timestamp * 30.0));
    const Rigid3d gt = first_from_world * sequence.WorldFromCam(i);
    sum2 += (gt.translation() - p.world_from_cam.translation()).squaredNorm();
  }
  run.ate_rmse = std::sqrt(sum2 / static_cast<double>(trajectory.size()));
  return run;
}

// The geometric test catches the persons' points without a box. On this small office (3 persons
// filling much of a 320x240 view) it does not yet rescue the trajectory: 98 mm with the test,
// 89 mm without, 71 and 80 of 80 frames tracked (measured; on bonn-crowd-a it does, README).
TEST(StaticProbabilityTest, BoxlessMoversAreJudgedMoving) {
  const SyntheticOffice sequence(80, 320, 240, 7, 3);
  const BoxlessRun on = TrackWithoutBoxes(sequence, true);
  const BoxlessRun off = TrackWithoutBoxes(sequence, false);
  RecordProperty("ate_on_mm", static_cast<int>(std::lround(on.ate_rmse * 1000)));
  RecordProperty("ate_off_mm", static_cast<int>(std::lround(off.ate_rmse * 1000)));
  EXPECT_GT(on.judged_dynamic, 0);  // the persons' points are caught without a box
  EXPECT_EQ(off.judged_dynamic, 0);
  EXPECT_GE(on.tracked, 60);
}

// What tracking reports per keypoint (MatchState) covers the frame's matches only: its pose
// inliers are the frame's inlier count, and what the geometric test keeps out of the pose is what
// it judged below the threshold this frame; a new keyframe's own fresh points (at the creation
// prior, never matched) are not among them.
TEST(StaticProbabilityTest, MatchStatesCountTheFramesMatchesOnly) {
  const SyntheticOffice sequence(30, 320, 240, 7, 2);
  SystemOptions options;
  options.tracking.static_test = true;
  System system(sequence.GetCamera(), options);
  int keyframes_checked = 0;
  for (size_t i = 0; i < sequence.Size(); ++i) {
    const FrameData frame = sequence.Load(i);
    const TrackResult r = system.TrackFrame(frame, frame.depth, {});
    if (!r.tracked || i == 0) continue;
    ASSERT_EQ(r.match_state.size(), r.keypoints.size());
    std::array<int, 5> count{};
    for (MatchState s : r.match_state) ++count[static_cast<size_t>(s)];
    if (r.quality != PoseQuality::kGood) continue;
    EXPECT_EQ(count[static_cast<size_t>(MatchState::kPoseInlier)], r.inliers) << "frame " << i;
    EXPECT_LE(count[static_cast<size_t>(MatchState::kUnconfirmed)] +
                  count[static_cast<size_t>(MatchState::kJudgedMoving)],
              r.geometric_dynamic)
        << "frame " << i;
    keyframes_checked += r.new_keyframe;
  }
  system.Shutdown();
  EXPECT_GT(keyframes_checked, 0);
}

// A new keyframe's points wait for a confirming view before they enter the pose and local BA
// (MapPoint::admitted): with no box at all, few of those made from the walking persons' pixels
// are ever admitted, far fewer than of the static scene's; with the test off every point is
// admitted at once. The confirming view may be the frame before the keyframe
// (static_confirm_in_last_frame): then part of the static points are admitted as they are made,
// and few of the movers'.
TEST(StaticProbabilityTest, NewPointsOfMoversAreNeverAdmitted) {
  const SyntheticOffice sequence(40, 320, 240, 7, 3);
  // moving, moving admitted, static, static admitted, and of them admitted when made.
  using Counts = std::array<long long, 6>;
  auto run = [&sequence](bool static_test, bool confirm_in_last_frame) {
    SystemOptions options;
    options.tracking.static_test = static_test;
    options.tracking.static_params.confirm_in_last_frame = confirm_in_last_frame;
    System system(sequence.GetCamera(), options);
    std::vector<std::pair<bool, std::shared_ptr<const MapPoint>>> created;  // (moving, point)
    Counts counts{};
    for (size_t i = 0; i < sequence.Size(); ++i) {
      const FrameData frame = sequence.Load(i);
      const TrackResult r = system.TrackFrame(frame, frame.depth, {});
      const cv::Mat moving = sequence.MovingMask(i);
      for (const auto& [k, point] : r.created_points) {
        EXPECT_LT(k, r.keypoints.size());
        if (k >= r.keypoints.size()) continue;
        const cv::Point px(
            std::clamp(static_cast<int>(std::lround(r.keypoints[k].pt.x)), 0, moving.cols - 1),
            std::clamp(static_cast<int>(std::lround(r.keypoints[k].pt.y)), 0, moving.rows - 1));
        const bool is_moving = moving.at<uint8_t>(px) > 127;
        // Created below the threshold: not admitted yet (with the test on) unless the frame
        // before confirmed it.
        if (!confirm_in_last_frame) {
          EXPECT_EQ(point->admitted, !static_test);
        }
        counts[is_moving ? 4 : 5] += point->admitted;
        created.emplace_back(is_moving, point);
      }
    }
    system.Shutdown();
    for (const auto& [is_moving, point] : created) {
      counts[is_moving ? 0 : 2] += 1;
      counts[is_moving ? 1 : 3] += point->admitted;
    }
    return counts;
  };
  const Counts on = run(true, false), confirmed = run(true, true), off = run(false, false);
  auto record = [](const std::string& prefix, const Counts& c) {
    const char* names[] = {"moving_created", "moving_admitted", "static_created",
                           "static_admitted", "moving_at_creation", "static_at_creation"};
    for (size_t k = 0; k < c.size(); ++k)
      RecordProperty(prefix + names[k], static_cast<int>(c[k]));
  };
  record("", on);
  record("confirmed_", confirmed);
  ASSERT_GT(on[0], 20);
  ASSERT_GT(on[2], 200);
  // Measured: 42 of 176 movers' new points admitted (24 %; box persons at 320x240 without a
  // box, several walking along the line of sight), 358 of 854 static ones (42 %; the rest are
  // not seen again in 40 frames or not decisively). On the photo office with YOLOX-nano: 4 % and
  // 55 % (docs/ablation.md).
  auto rate = [](long long a, long long b) {
    return static_cast<double>(a) / static_cast<double>(b);
  };
  EXPECT_EQ(on[4] + on[5], 0);
  EXPECT_LT(rate(on[1], on[0]), 0.3);
  EXPECT_GT(rate(on[3], on[2]), 0.3);
  EXPECT_LT(rate(on[1], on[0]), 0.7 * rate(on[3], on[2]));
  EXPECT_EQ(off[1], off[0]);
  EXPECT_EQ(off[3], off[2]);
  // Confirmed by the frame before, measured: 419 of 840 static and 43 of 180 movers' new points
  // admitted as they are made; 595 and 66 ever admitted.
  ASSERT_GT(confirmed[0], 20);
  ASSERT_GT(confirmed[2], 200);
  EXPECT_GT(rate(confirmed[5], confirmed[2]), 0.1);
  EXPECT_LT(rate(confirmed[4], confirmed[0]), 0.5 * rate(confirmed[5], confirmed[2]));
  EXPECT_LT(rate(confirmed[1], confirmed[0]), 0.7 * rate(confirmed[3], confirmed[2]));
}

}  // namespace
}  // namespace ademono
