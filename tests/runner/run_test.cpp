// The runner and the writer on a short synthetic office (walking persons, exact depth, truth
// boxes): the report's per-frame records add up to its totals, the run folder holds every output
// with the "ademono.run/1" summary, a second run (one without prefetch, one preparing three
// frames at once) writes identical trajectories, and a provider failure leaves no output.
#include "ademono/runner/run.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

#include "ademono/core/error.h"
#include "ademono/runner/run_writer.h"
#include "runner_test_util.h"

namespace fs = std::filesystem;

namespace ademono {
namespace {

using runner_test::FrameDepth;
using runner_test::TruthBoxes;

constexpr size_t kFrames = 24;

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

size_t PoseLines(const fs::path& path) {
  std::istringstream in(ReadText(path));
  size_t n = 0;
  for (std::string line; std::getline(in, line);) n += !line.empty() && line[0] != '#';
  return n;
}

std::set<std::string> Keys(const nlohmann::json& j) {
  std::set<std::string> keys;
  for (const auto& [key, value] : j.items()) keys.insert(key);
  return keys;
}

class RunnerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = runner_test::TempDir("run");
    runner_test::RenderOffice(dir_ / "office", kFrames);
    report_ = std::make_unique<RunReport>(Run(true, true));  // shared: each run takes seconds
  }
  static void TearDownTestSuite() {
    report_.reset();
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  static RunReport Run(bool overlap, bool truth = false, int prefetch_frames = 1) {
    const auto sequence = OpenSequence("tum:" + (dir_ / "office").string());
    FrameDepth depth;
    TruthBoxes boxes(dir_ / "office" / "detections.jsonl");
    RunOptions options;
    options.pipeline.overlap = overlap;
    options.pipeline.prefetch_frames = prefetch_frames;
    options.score_synthetic_truth = truth;
    options.config = "built-in";
    return RunSequence(*sequence, &depth, &boxes, options);
  }
  static fs::path dir_;
  static std::unique_ptr<RunReport> report_;  // Run(true, true)
};
fs::path RunnerTest::dir_;
std::unique_ptr<RunReport> RunnerTest::report_;

TEST_F(RunnerTest, ReportAddsUpAndIsAccurate) {
  const RunReport& r = *report_;
  EXPECT_EQ(r.frames, kFrames);
  ASSERT_EQ(r.per_frame.size(), kFrames);
  EXPECT_EQ(r.depth, "frame-depth");
  EXPECT_EQ(r.detector, "truth-boxes");
  EXPECT_EQ(r.dataset, "tum:" + (dir_ / "office").string());
  size_t tracked = 0, keyframes = 0;
  long long kept = 0, boxes = 0;
  for (size_t i = 0; i < kFrames; ++i) {
    const FrameReport& f = r.per_frame[i];
    EXPECT_EQ(f.frame, i);
    tracked += f.tracked;
    keyframes += f.keyframe;
    kept += f.filter.kept;
    boxes += f.filter.boxes_small + f.filter.boxes_large;
    EXPECT_EQ(f.tracked, f.state == TrackingState::kOk) << i;
    EXPECT_GE(f.ms.extraction_ms, 0.0);
  }
  EXPECT_EQ(tracked, r.Tracked());
  EXPECT_TRUE(r.per_frame.front().keyframe);  // the map starts with a keyframe
  EXPECT_GE(keyframes, r.keyframes);          // some may have been culled since
  EXPECT_EQ(kept, r.filter_totals.kept);
  EXPECT_EQ(boxes, r.filter_totals.boxes_small + r.filter_totals.boxes_large);
  EXPECT_GT(boxes, 0);  // the persons are in view
  EXPECT_GT(r.filter_totals.RemovedDynamic(), 0);
  ASSERT_TRUE(r.accuracy.has_value()) << r.accuracy_note;
  EXPECT_EQ(r.accuracy->matched_poses, r.Tracked());
  EXPECT_LT(r.accuracy->ate_se3_rmse_m, 0.05);
  EXPECT_NEAR(r.accuracy->sim3_scale, 1.0, 0.1);  // exact depth: metric scale
  EXPECT_EQ(r.ground_truth.size(), r.Tracked());
  for (size_t i = 0; i < r.ground_truth.size(); ++i)
    EXPECT_EQ(r.ground_truth[i].timestamp, r.trajectory[i].timestamp);
  ASSERT_TRUE(r.truth.has_value());  // masks/ scored
  EXPECT_GT(r.truth->moving_keypoints, 0);
  EXPECT_GT(r.truth->moving_removed, 0);
  EXPECT_EQ(r.map_cloud.size(), r.map_points);
  for (const char* stage :
       {"extraction", "depth", "detection", "filter", "tracking", "local_mapping"}) {
    ASSERT_TRUE(r.timing.count(stage)) << stage;
    EXPECT_GE(r.timing.at(stage).p95_ms, r.timing.at(stage).median_ms) << stage;
  }
}

TEST_F(RunnerTest, WriterWritesTheRunFolderWithTheSummarySchema) {
  const RunReport& r = *report_;
  const fs::path out = dir_ / "out";
  WriteRunOutputs(r, out);
  EXPECT_EQ(PoseLines(out / "trajectory.tum"), r.Tracked());
  EXPECT_EQ(PoseLines(out / "trajectory.kitti"), r.Tracked());
  EXPECT_EQ(PoseLines(out / "keyframes.tum"), r.keyframes);
  EXPECT_EQ(PoseLines(out / "groundtruth.tum"), r.Tracked());
  EXPECT_NE(ReadText(out / "map.ply").find("element vertex " + std::to_string(r.map_points) + "\n"),
            std::string::npos);

  const nlohmann::json s = nlohmann::json::parse(ReadText(out / "summary.json"));
  EXPECT_EQ(s["schema"], "ademono.run/1");
  EXPECT_EQ(Keys(s),
            (std::set<std::string>{"schema",    "dataset",   "config",        "depth",
                                   "detector",  "seed",      "deterministic", "filters",
                                   "frames",    "partial",   "tracked",       "untracked",
                                   "lost",      "keyframes", "map_points",    "wall_seconds",
                                   "fps",       "timing",    "filter_counts", "accuracy",
                                   "per_frame", "loops",     "weak_poses",    "geometric_test",
                                   "map_scale"}));
  // The dataset has depth images: the map's scale against them, per keyframe (sensor depth:
  // metric).
  EXPECT_EQ(Keys(s["map_scale"]),
            (std::set<std::string>{"keyframes", "median", "p10", "p90", "per_keyframe"}));
  ASSERT_TRUE(r.map_scale.has_value());
  EXPECT_EQ(s["map_scale"]["per_keyframe"].size(), r.map_scale->per_keyframe.size());
  EXPECT_GE(r.map_scale->per_keyframe.size(), r.keyframes / 2);
  EXPECT_NEAR(r.map_scale->median, 1.0, 0.01);
  // A short xyz sequence revisits no place away from the live map: no loop.
  EXPECT_TRUE(s["loops"].is_array());
  EXPECT_TRUE(s["loops"].empty());
  EXPECT_EQ(Keys(s["weak_poses"]),
            (std::set<std::string>{"few_static_points", "motion_model", "depth_odometry"}));
  EXPECT_EQ(Keys(s["geometric_test"]),
            (std::set<std::string>{"enabled", "matches_judged_dynamic", "map_points_culled"}));
  EXPECT_EQ(Keys(s["filters"]),
            (std::set<std::string>{"enhancement", "dynamic_removal", "distant"}));
  EXPECT_EQ(Keys(s["timing"]),
            (std::set<std::string>{"decode", "extraction", "keypoint_depth", "depth", "detection",
                                   "filter", "tracking", "local_mapping", "prefetch_wait",
                                   "tracking_thread", "prefetch_thread"}));
  // With the prefetch (overlap), everything but filters and tracking runs ahead on its thread.
  for (const char* stage :
       {"decode", "extraction", "keypoint_depth", "depth", "detection", "prefetch_thread"})
    EXPECT_EQ(s["timing"][stage]["thread"], "prefetch") << stage;
  for (const char* stage : {"filter", "tracking", "prefetch_wait", "tracking_thread"})
    EXPECT_EQ(s["timing"][stage]["thread"], "tracking") << stage;
  EXPECT_GT(s["timing"]["tracking_thread"]["median_ms"].get<double>(), 0.0);
  EXPECT_GT(s["timing"]["prefetch_thread"]["median_ms"].get<double>(), 0.0);
  EXPECT_EQ(
      Keys(s["accuracy"]),
      (std::set<std::string>{"matched_poses", "ate_se3_rmse_m", "ate_sim3_rmse_m", "sim3_scale",
                             "rpe_30_frames_trans_rmse_m", "rpe_30_frames_rot_rmse_deg"}));
  EXPECT_EQ(s["config"], "built-in");
  EXPECT_EQ(s["frames"], kFrames);
  EXPECT_EQ(s["tracked"].get<size_t>() + s["untracked"].get<size_t>(), kFrames);
  EXPECT_EQ(s["accuracy"]["ate_se3_rmse_m"].get<double>(), r.accuracy->ate_se3_rmse_m);
  ASSERT_EQ(s["per_frame"].size(), kFrames);
  long long removed_dynamic = 0;
  for (size_t i = 0; i < kFrames; ++i) {
    const nlohmann::json& f = s["per_frame"][i];
    EXPECT_EQ(Keys(f),
              (std::set<std::string>{"frame", "timestamp", "tracked", "state", "relocalised",
                                     "keyframe", "keypoints", "kept", "with_depth", "inliers",
                                     "dynamic_points_culled", "pose_quality", "static_points",
                                     "geometric_dynamic", "geometric_culled", "filter", "ms"}))
        << i;
    EXPECT_EQ(Keys(f["ms"]),
              (std::set<std::string>{"decode", "extraction", "keypoint_depth", "depth", "detection",
                                     "filter", "tracking", "mapping", "prefetch_wait",
                                     "tracking_thread_cpu", "prefetch_thread_cpu"}));
    EXPECT_EQ(f["frame"], i);
    EXPECT_EQ(f["state"], TrackingStateName(r.per_frame[i].state));
    EXPECT_EQ(f["kept"], r.per_frame[i].kept);
    EXPECT_EQ(f["static_points"], r.per_frame[i].tracked ? r.per_frame[i].inliers : 0);
    EXPECT_EQ(f["pose_quality"],
              r.per_frame[i].tracked ? PoseQualityName(r.per_frame[i].quality) : "none");
    removed_dynamic += f["filter"]["removed_small_box"].get<long long>() +
                       f["filter"]["removed_stage1"].get<long long>() +
                       f["filter"]["removed_stage2"].get<long long>() +
                       f["filter"]["removed_box_vote"].get<long long>();
  }
  EXPECT_EQ(s["filter_counts"]["removed_dynamic"].get<long long>(), removed_dynamic);
}

// A second run, without prefetch and without truth scoring, writes the same files.
TEST_F(RunnerTest, SecondAndSequentialRunWritesIdenticalOutputs) {
  const fs::path a = dir_ / "a", sequential = dir_ / "sequential";
  WriteRunOutputs(*report_, a);
  const RunReport second = Run(false);
  EXPECT_FALSE(second.truth.has_value());  // not asked for
  // Without prefetch every stage but the BA solve runs on the tracking thread.
  EXPECT_EQ(second.timing.at("extraction").thread, "tracking");
  EXPECT_EQ(second.timing.at("prefetch_thread").median_ms, 0.0);
  // CPU time, measured (extraction included); not compared with the wall-time stages, which a
  // loaded machine inflates (CI at load 25: 12.7 ms of CPU against 22.4 ms of wall extraction).
  EXPECT_GT(second.timing.at("tracking_thread").median_ms, 0.0);
  EXPECT_EQ(second.timing.at("tracking_thread").thread, "tracking");
  WriteRunOutputs(second, sequential);
  for (const char* file :
       {"trajectory.tum", "trajectory.kitti", "keyframes.tum", "map.ply", "groundtruth.tum"}) {
    const std::string first = ReadText(a / file);
    EXPECT_FALSE(first.empty()) << file;
    EXPECT_EQ(first, ReadText(sequential / file)) << file;
  }
  nlohmann::json s1 = nlohmann::json::parse(ReadText(a / "summary.json"));
  nlohmann::json s2 = nlohmann::json::parse(ReadText(sequential / "summary.json"));
  for (nlohmann::json* s : {&s1, &s2}) {  // everything but the times
    s->erase("wall_seconds"), s->erase("fps"), s->erase("timing");
    for (auto& f : (*s)["per_frame"]) f.erase("ms");
  }
  EXPECT_EQ(s1, s2);
}

// Three frames prepared at once (as a slow depth network gets two): the same outputs.
TEST_F(RunnerTest, DeeperPrefetchWritesIdenticalOutputs) {
  const fs::path a = dir_ / "a3", deep = dir_ / "deep";
  WriteRunOutputs(*report_, a);
  const RunReport third = Run(true, false, 3);
  EXPECT_EQ(third.timing.at("extraction").thread, "prefetch");
  WriteRunOutputs(third, deep);
  for (const char* file :
       {"trajectory.tum", "trajectory.kitti", "keyframes.tum", "map.ply", "groundtruth.tum"}) {
    const std::string first = ReadText(a / file);
    EXPECT_FALSE(first.empty()) << file;
    EXPECT_EQ(first, ReadText(deep / file)) << file;
  }
}

TEST_F(RunnerTest, ProviderFailureThrowsAndWritesNothing) {
  class FailsAtFrame5 : public FrameDepth {
   public:
    cv::Mat Depth(const FrameData& frame, const Camera& camera) override {
      if (frame.index == 5) ThrowInputError(frame.name, "no depth for this frame");
      return FrameDepth::Depth(frame, camera);
    }
  };
  const auto sequence = OpenSequence("tum:" + (dir_ / "office").string());
  for (const int prefetch : {1, 3, 0}) {  // 0: no overlap
    const bool overlap = prefetch > 0;
    FailsAtFrame5 depth;
    RunOptions options;
    options.pipeline.overlap = overlap;
    options.pipeline.prefetch_frames = std::max(1, prefetch);
    size_t frames_seen = 0;
    options.on_frame = [&](const FrameData&, const std::vector<Detection>&, const TrackResult&) {
      ++frames_seen;
    };
    const fs::path out = dir_ / "failed";
    EXPECT_THROW(WriteRunOutputs(RunSequence(*sequence, &depth, nullptr, options), out),
                 InputError);
    EXPECT_EQ(frames_seen, 5u) << prefetch;  // frames 0-4, in order, then the error
    EXPECT_FALSE(fs::exists(out));
  }
}

// The dataset's depth images are decoded only for a provider that reads them: a network-like
// provider gets frames without (and the same trajectory comes out of the same depths).
TEST_F(RunnerTest, DepthImagesAreDecodedOnlyForAProviderThatReadsThem) {
  class ReadsNothing : public DepthProvider {
   public:
    std::string Name() const override { return "reads-nothing"; }
    cv::Mat Depth(const FrameData& frame, const Camera& camera) override {
      saw_depth = saw_depth || !frame.depth.empty();
      return sensor.Depth(source->Load(frame.index), camera);
    }
    FrameDepth sensor;
    const Sequence* source = nullptr;
    bool saw_depth = false;
  };
  const auto sequence = OpenSequence("tum:" + (dir_ / "office").string());
  RunOptions options;
  options.pipeline.end = 30;
  ReadsNothing network;
  network.source = sequence.get();
  const RunReport without = RunSequence(*sequence, &network, nullptr, options);
  EXPECT_FALSE(network.saw_depth);
  RunOptions realtime = options;  // the real-time feed loads frames the same way
  realtime.realtime = RealtimeOptions{};
  realtime.realtime->pace = false;
  realtime.realtime->queue = 100;
  RunSequence(*sequence, &network, nullptr, realtime);
  EXPECT_FALSE(network.saw_depth);
  FrameDepth sensor;
  const RunReport with = RunSequence(*sequence, &sensor, nullptr, options);
  ASSERT_GT(with.trajectory.size(), 20u);
  ASSERT_EQ(without.trajectory.size(), with.trajectory.size());
  for (size_t i = 0; i < with.trajectory.size(); ++i)
    EXPECT_TRUE(
        without.trajectory[i].world_from_cam.isApprox(with.trajectory[i].world_from_cam, 1e-12));
}

TEST(RunAccuracyTest, ComputedWithEvalOrExplained) {
  Trajectory gt;
  for (int i = 0; i < 40; ++i) {
    Rigid3d pose = Rigid3d::Identity();
    pose.translation() = Eigen::Vector3d(0.1 * i, 0.02 * i * i / 40.0, std::sin(0.2 * i));
    gt.push_back({i / 30.0, pose});
  }
  std::string note;
  const std::optional<RunAccuracy> same = ComputeAccuracy(gt, gt, &note);
  ASSERT_TRUE(same.has_value()) << note;
  EXPECT_EQ(same->matched_poses, 40u);
  EXPECT_NEAR(same->ate_se3_rmse_m, 0.0, 1e-9);
  EXPECT_NEAR(same->sim3_scale, 1.0, 1e-9);
  EXPECT_NEAR(same->rpe_30_frames_trans_rmse_m, 0.0, 1e-9);
  // The estimate at half scale: se3 cannot undo it, sim3 can (scale 2 from estimate to truth).
  Trajectory half = gt;
  for (StampedPose& p : half) p.world_from_cam.translation() *= 0.5;
  const std::optional<RunAccuracy> scaled = ComputeAccuracy(gt, half, &note);
  ASSERT_TRUE(scaled.has_value());
  EXPECT_GT(scaled->ate_se3_rmse_m, 0.1);
  EXPECT_NEAR(scaled->ate_sim3_rmse_m, 0.0, 1e-9);
  EXPECT_NEAR(scaled->sim3_scale, 2.0, 1e-9);

  EXPECT_FALSE(ComputeAccuracy({}, gt, &note).has_value());
  EXPECT_EQ(note, "dataset has no ground truth");
  EXPECT_FALSE(ComputeAccuracy(gt, Trajectory(gt.begin(), gt.begin() + 2), &note).has_value());
  EXPECT_EQ(note, "fewer than 3 tracked frames");
  Trajectory far = gt;
  for (StampedPose& p : far) p.timestamp += 100.0;  // nothing associates
  EXPECT_FALSE(ComputeAccuracy(gt, far, &note).has_value());
  EXPECT_EQ(note.rfind("ATE not computed: ", 0), 0u) << note;
}

TEST(RunReportTest, StateNames) {
  EXPECT_STREQ(TrackingStateName(TrackingState::kNotInitialized), "not_initialized");
  EXPECT_STREQ(TrackingStateName(TrackingState::kOk), "ok");
  EXPECT_STREQ(TrackingStateName(TrackingState::kLost), "lost");
}

}  // namespace
}  // namespace ademono
