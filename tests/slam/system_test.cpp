#include "ademono/slam/system.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "ademono/core/error.h"
#include "slam_test_util.h"

namespace ademono {
namespace {

using testing_util::Fault;
using testing_util::Slice;

SystemOptions TestOptions() {
  SystemOptions options;
  options.depth.min_depth = 0.3;
  options.depth.max_depth = 6.0;
  return options;
}

// Every frame through System with its sensor depth (non-finite readings as 0, as the sensor
// provider gives them); the prefetching pipeline is tested in tests/runner.
Trajectory RunSlice(const Sequence& sequence, const SystemOptions& options,
                    std::vector<TrackResult>* results = nullptr) {
  System system(sequence.GetCamera(), options);
  for (size_t i = 0; i < sequence.Size(); ++i) {
    const FrameData frame = sequence.Load(i);
    const TrackResult r = system.TrackFrame(frame, testing_util::SensorDepth(frame), {});
    if (results != nullptr) results->push_back(r);
  }
  system.Shutdown();
  return system.FrameTrajectory();
}

// Largest position error of the estimate against the ground truth expressed in the first
// frame's camera (the SLAM world is the first camera).
double MaxPositionError(const Sequence& sequence, const Trajectory& trajectory) {
  const Rigid3d first_from_world = sequence.Load(0).world_from_cam_gt->inverse();
  double worst = 0;
  for (const StampedPose& p : trajectory) {
    const size_t i = static_cast<size_t>(std::lround(p.timestamp * 30.0));
    const Rigid3d gt = first_from_world * *sequence.Load(i).world_from_cam_gt;
    worst = std::max(worst, (gt.translation() - p.world_from_cam.translation()).norm());
  }
  return worst;
}

TEST(SystemTest, TracksAShortSliceAccurately) {
  const auto sequence = Slice(0, 40);
  std::vector<TrackResult> results;
  const Trajectory trajectory = RunSlice(*sequence, TestOptions(), &results);
  ASSERT_EQ(trajectory.size(), 40u);
  EXPECT_LT(MaxPositionError(*sequence, trajectory), 0.03);
  EXPECT_TRUE(results.front().new_keyframe);
  for (const TrackResult& r : results) EXPECT_GT(r.num_kept, 300);
}

TEST(SystemTest, SurvivesNoDepthBlackAndDuplicatedFrames) {
  // 60 frames: frame 15 without depth, frame 30 black, frame 44 twice.
  const auto sequence = Slice(0, 60, {{15, Fault::kNoDepth}, {30, Fault::kBlack}}, {44});
  std::vector<TrackResult> results;
  const Trajectory trajectory = RunSlice(*sequence, TestOptions(), &results);
  ASSERT_EQ(results.size(), 61u);
  // Nothing to track in a black frame: it keeps the constant-velocity pose, reported as weak
  // (tracking.weak_pose_max_frames), instead of a gap.
  EXPECT_TRUE(results[30].tracked);
  EXPECT_EQ(results[30].quality, PoseQuality::kMotionModel);
  EXPECT_EQ(results[30].inliers, 0);
  EXPECT_EQ(results[30].num_keypoints, 0);
  EXPECT_TRUE(results[15].tracked);  // 2-dof residuals only
  for (size_t i = 32; i < results.size(); ++i) EXPECT_TRUE(results[i].tracked) << "frame " << i;
  EXPECT_GE(trajectory.size(), 59u);
  EXPECT_LT(MaxPositionError(*sequence, trajectory), 0.05);
}

// Off the map, each weak pose is measured on the previous frame's depths (tracking.
// depth_odometry) rather than extrapolated: frames 0-29 of seq-a, then a cut to frames 300-311,
// which that map has not seen. The cut's first frames get wrong poses either way (false matches
// across the cut, a keyframe made on them); from the fifth frame after it the map is of no use
// and the frame-to-frame motion follows the ground truth, the constant-velocity prediction (the
// option off) does not.
TEST(SystemTest, OffTheMapTheLastFramesDepthsMeasureThePose) {
  std::vector<testing_util::FaultySequence::Entry> entries;
  for (size_t s = 0; s < 30; ++s) entries.push_back({s});
  for (size_t s = 300; s < 312; ++s) entries.push_back({s});
  const testing_util::FaultySequence sequence(OpenSequence(testing_util::SevenScenesSpec()),
                                              entries);
  constexpr size_t kSettled = 35;
  // The mean frame-to-frame translation error from kSettled on. (Off, those frames rest on a few
  // false map matches or on the prediction.)
  auto mean_step_error = [&](const SystemOptions& options, std::vector<TrackResult>& results) {
    const Trajectory trajectory = RunSlice(sequence, options, &results);
    std::map<size_t, Rigid3d> world_from_cam;
    for (const StampedPose& p : trajectory)
      world_from_cam[static_cast<size_t>(std::lround(p.timestamp * 30.0))] = p.world_from_cam;
    double sum = 0;
    for (size_t i = kSettled; i < entries.size(); ++i) {
      if (!world_from_cam.count(i) || !world_from_cam.count(i - 1)) return 1e9;
      const Rigid3d estimate = world_from_cam[i - 1].inverse() * world_from_cam[i];
      const Rigid3d truth = sequence.Load(i - 1).world_from_cam_gt->inverse() *
                            *sequence.Load(i).world_from_cam_gt;
      sum += (estimate.translation() - truth.translation()).norm();
    }
    return sum / static_cast<double>(entries.size() - kSettled);
  };
  std::vector<TrackResult> results;
  const double with = mean_step_error(TestOptions(), results);
  ASSERT_EQ(results.size(), entries.size());
  for (size_t i = kSettled; i < results.size(); ++i) {
    EXPECT_TRUE(results[i].tracked) << "frame " << i;
    EXPECT_EQ(results[i].quality, PoseQuality::kDepthOdometry) << "frame " << i;
    EXPECT_GE(results[i].inliers, 100) << "frame " << i;
  }
  SystemOptions off = TestOptions();
  off.tracking.depth_odometry = false;
  std::vector<TrackResult> off_results;
  const double without = mean_step_error(off, off_results);
  ASSERT_EQ(off_results.size(), entries.size());
  for (size_t i = kSettled; i < off_results.size(); ++i)
    EXPECT_NE(off_results[i].quality, PoseQuality::kDepthOdometry) << "frame " << i;
  RecordProperty("mean_step_error_um", static_cast<int>(std::lround(with * 1e6)));
  RecordProperty("mean_step_error_off_um", static_cast<int>(std::lround(without * 1e6)));
  EXPECT_LT(with, 0.004);  // 2.4 mm measured
  EXPECT_LT(with, 0.5 * without);  // 9.6 mm measured
}

TEST(SystemTest, RepeatedRunsGiveIdenticalTrajectories) {
  const auto sequence = Slice(100, 145);
  const Trajectory a = RunSlice(*sequence, TestOptions());
  const Trajectory b = RunSlice(*sequence, TestOptions());
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i)
    EXPECT_TRUE(a[i].world_from_cam.matrix() == b[i].world_from_cam.matrix()) << i;
}

TEST(SystemTest, KeypointDepthsRejectInvalidAndEdgeReadings) {
  cv::Mat depth(20, 20, CV_32FC1, cv::Scalar(2.0f));
  depth(cv::Rect(10, 0, 10, 20)).setTo(3.0f);  // a step edge at x = 10
  depth.at<float>(5, 3) = 0.f;                 // a hole
  FrameDepthOptions options;
  const std::vector<cv::KeyPoint> keypoints{{cv::Point2f(4, 10), 1},
                                            {cv::Point2f(9, 10), 1},
                                            {cv::Point2f(3, 6), 1},
                                            {cv::Point2f(50, 10), 1}};
  const std::vector<float> d = System::KeypointDepths(keypoints, depth, options);
  EXPECT_FLOAT_EQ(d[0], 2.0f);
  EXPECT_LT(d[1], 0);  // next to the edge
  EXPECT_LT(d[2], 0);  // next to the hole
  EXPECT_LT(d[3], 0);  // outside the image
  options.edge_radius = 0;
  EXPECT_FLOAT_EQ(System::KeypointDepths(keypoints, depth, options)[1], 2.0f);
  EXPECT_TRUE(System::KeypointDepths(keypoints, cv::Mat(), options)[0] < 0);
}

TEST(SystemOptionsTest, YamlErrorsNameTheFile) {
  const std::filesystem::path path = "/configs/bad.yaml";
  auto expect_error = [&](const std::string& text, const std::string& needle) {
    try {
      SystemOptions::FromYaml(YAML::Load(text), path);
      FAIL() << "expected InputError for " << text;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path.string()), std::string::npos) << message;
      EXPECT_NE(message.find(needle), std::string::npos) << message;
    }
  };
  expect_error("tracking:\n  min_inliers: many\n", "tracking.min_inliers: cannot parse 'many'");
  expect_error("tracking:\n  bogus_key: 1\n", "unknown key 'tracking.bogus_key'");
  expect_error("optimizer:\n  pose_rounds: [1, 2]\n",
               "optimizer.pose_rounds: cannot parse '[1, 2]'");
  expect_error("mapping: [1]\n", "'mapping' must be a map");
  expect_error("depth:\n  min_depth: 5\n  max_depth: 1\n", "min_depth");
  expect_error("nonsense_section: {}\n", "nonsense_section");
  const SystemOptions ok =
      SystemOptions::FromYaml(YAML::Load("tracking:\n  min_inliers: 40\n"), path);
  EXPECT_EQ(ok.tracking.min_inliers, 40);
  EXPECT_EQ(ok.tracking.min_init_points, TrackingOptions().min_init_points);
}

}  // namespace
}  // namespace ademono
