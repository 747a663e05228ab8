// The run report's data side: reading a run folder (schema ademono.run/1), alignment with the eval
// module, thumbnail choice, critical path, map subsampling, comparison, bad input, and the page.
#include "ademono/report/report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/core/geometry.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace ademono {
namespace {

constexpr int kFrames = 40;
constexpr int kWorstFrame = 25;       // the estimate is pushed off the ground truth here
constexpr int kDynamicFrame = 10;     // most stage-1 removals
constexpr int kRelocFrame = 32;       // relocalised after frames 30 and 31 were lost

std::string Padded(int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame-%06d.jpg", frame);
  return name;
}

Eigen::Vector3d GtPosition(int i) {
  const double a = 2 * M_PI * i / kFrames;
  return {2.0 * std::cos(a), 0.1 * std::sin(3 * a), 1.5 * std::sin(a)};
}

// The estimate lives in its own world frame: est = world_from_gt * gt (a rigid motion), plus
// `bump` metres on x at kWorstFrame and `noise` metres alternating in sign.
const Rigid3d kEstFromGt = MakeRigid3d(
    Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY())), {0.3, -0.2, 1.0});

struct FixtureOptions {
  bool ground_truth = true;
  bool viz = true;
  bool map = true;
  double noise = 0.0;
  double bump = 0.3;
  std::string dataset = "synth:office";
};

// Writes a run folder in the unified schema.
void WriteRunFolder(const fs::path& dir, const FixtureOptions& o = {}) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  Trajectory gt, est, kfs;
  json per_frame = json::array();
  for (int i = 0; i < kFrames; ++i) {
    const double t = 100.0 + 0.1 * i;
    const bool lost = i == 30 || i == 31;
    Rigid3d world_from_cam = Rigid3d::Identity();
    world_from_cam.translation() = GtPosition(i);
    gt.push_back({t, world_from_cam});
    if (!lost) {
      Rigid3d e = kEstFromGt * world_from_cam;
      e.translation().x() += (i == kWorstFrame ? o.bump : 0.0) + (i % 2 ? o.noise : -o.noise);
      est.push_back({t, e});
      if (i % 5 == 0) kfs.push_back({t, e});
    }
    json filter = {{"boxes_small", 0},        {"boxes_large", 1},
                   {"removed_enhancement", 50}, {"removed_small_box", 0},
                   {"removed_stage1", i == kDynamicFrame ? 40 : 3},
                   {"removed_stage2", 1},      {"removed_box_vote", 0},
                   {"removed_distant", 7},     {"distant_candidates", 14},
                   {"stage1_compensated", 1},  {"kept", 300}};
    per_frame.push_back(
        {{"frame", i},
         {"timestamp", t},
         {"tracked", !lost},
         {"state", lost ? "lost" : "ok"},
         {"relocalised", i == kRelocFrame},
         {"keyframe", !lost && i % 5 == 0},
         {"keypoints", 400},
         {"kept", 300},
         {"with_depth", 280},
         {"inliers", lost ? 0 : 150},
         {"dynamic_points_culled", 0},
         {"filter", filter},
         {"ms",
          {{"extraction", 3.0}, {"depth", 4.0}, {"detection", 2.0}, {"filter", 1.0},
           {"tracking", 10.0 + (i % 3)}, {"mapping", 5.0}}},
         {"depth_scale", 1.0 + 0.01 * i}});
    if (i >= 2 && !lost) per_frame.back()["scale_sigma"] = 0.1 / i;
  }
  json summary = {
      {"schema", "ademono.run/1"},
      {"dataset", o.dataset},
      {"config", "configs/tum.yaml"},
      {"depth", "simulated"},
      {"detector", "cache"},
      {"seed", 1},
      {"deterministic", true},
      {"filters", {{"enhancement", true}, {"dynamic_removal", true}, {"distant", true}}},
      {"frames", kFrames},
      {"tracked", kFrames - 2},
      {"untracked", 2},
      {"lost", 2},
      {"keyframes", kfs.size()},
      {"map_points", 1000},
      {"wall_seconds", 2.0},
      {"fps", 20.0},
      {"timing", json::object()},
      {"filter_counts", {{"kept", 300 * kFrames}}},
      {"map_scale",
       {{"keyframes", 2},
        {"median", 1.25},
        {"p10", 1.2},
        {"p90", 1.3},
        {"per_keyframe",
         {{{"frame", 5}, {"samples", 80}, {"scale", 1.2}},
          {{"frame", 10}, {"samples", 90}, {"scale", 1.3}}}}}},
      {"per_frame", per_frame}};
  WriteTextFileAtomic(dir / "summary.json", summary.dump(1));
  WriteTumTrajectory(dir / "trajectory.tum", est);
  WriteTumTrajectory(dir / "keyframes.tum", kfs);
  if (o.ground_truth) WriteTumTrajectory(dir / "groundtruth.tum", gt);
  if (o.map) {
    std::ofstream ply(dir / "map.ply");
    ply << "ply\nformat ascii 1.0\nelement vertex 1000\nproperty float x\nproperty float y\n"
           "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
           "end_header\n";
    for (int i = 0; i < 1000; ++i) {
      const Eigen::Vector3d p = kEstFromGt * Eigen::Vector3d(0.01 * i, 1.0, -0.005 * i);
      ply << p.x() << " " << p.y() << " " << p.z() << " 10 20 30\n";
    }
  }
  if (o.viz) {
    fs::create_directories(dir / "viz");
    for (int f : {kDynamicFrame, kWorstFrame, kRelocFrame}) {
      cv::Mat image(480, 640, CV_8UC3, cv::Scalar(40, 80, 120));
      cv::circle(image, {320, 240}, 50, cv::Scalar(0, 255, 0), -1);
      cv::imwrite((dir / "viz" / Padded(f)).string(), image);
    }
  }
}

class ReportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("ademono_report_test_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }
  fs::path root_;
};

TEST_F(ReportTest, AlignsTheEstimateOntoTheGroundTruthWithTheEvalModule) {
  WriteRunFolder(root_ / "run", {.bump = 0.0});
  const json data = RunReportData(ReadRunFolder(root_ / "run"), ReportOptions());
  EXPECT_EQ(data["kind"], "run");
  EXPECT_EQ(data["alignment"], "se3");
  const json& traj = data["traj"];
  // A pure rigid motion between the two: se3 alignment recovers it, every error ~ 0.
  ASSERT_EQ(traj["err"].size(), kFrames - 2u);
  for (const auto& e : traj["err"]) EXPECT_LT(e.get<double>(), 1e-4);
  EXPECT_NEAR(traj["scale"].get<double>(), 1.0, 1e-12);
  // Aligned estimate back in the ground-truth frame: frame 3 sits at GtPosition(3).
  const Eigen::Vector3d p3 = GtPosition(3);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(traj["est"][a][3].get<double>(), p3[a], 2e-4);
  EXPECT_NEAR(traj["t"][3].get<double>(), 0.3, 1e-9);
  // Keyframes and map points are moved by the same alignment (first map point: (0, 1, 0)).
  EXPECT_NEAR(traj["kf"][1][0].get<double>(), GtPosition(0).y(), 2e-4);
  EXPECT_EQ(data["map"]["count"], 1000);
}

// A run without depth has no metric scale: its report aligns with sim3 (se3 would score the
// unit of its two-view start) unless an alignment is asked for; a camera height gives it metres.
TEST_F(ReportTest, ARunWithoutMetricScaleIsAlignedWithSim3) {
  WriteRunFolder(root_ / "run", {.bump = 0.0});
  json summary = json::parse(ReadTextFile(root_ / "run" / "summary.json"));
  EXPECT_TRUE(RunHasMetricScale(ReadRunFolder(root_ / "run")));  // simulated depth
  summary["depth"] = "none";
  WriteTextFileAtomic(root_ / "run" / "summary.json", summary.dump());
  const RunFolder none = ReadRunFolder(root_ / "run");
  EXPECT_FALSE(RunHasMetricScale(none));
  const json data = RunReportData(none, ReportOptions());
  EXPECT_EQ(data["alignment"], "sim3");
  EXPECT_NE(data.value("alignment_reason", std::string()).find("no metric scale"),
            std::string::npos);
  ReportOptions asked;
  asked.sim3_without_metric_scale = false;  // `ademono report --align se3`
  EXPECT_EQ(RunReportData(none, asked)["alignment"], "se3");
  EXPECT_FALSE(RunReportData(none, asked).contains("alignment_reason"));
  asked.alignment = Alignment::kOrigin;
  asked.sim3_without_metric_scale = true;  // only se3 is replaced
  EXPECT_EQ(RunAlignment(none, asked), Alignment::kOrigin);

  summary["ground_scale"] = {{"camera_height", 1.65}, {"estimates", 3}};
  WriteTextFileAtomic(root_ / "run" / "summary.json", summary.dump());
  const RunFolder road = ReadRunFolder(root_ / "run");
  EXPECT_TRUE(RunHasMetricScale(road));
  EXPECT_EQ(RunReportData(road, ReportOptions())["alignment"], "se3");
}

TEST_F(ReportTest, ChoosesThumbnailsAtWorstErrorRelocalisationAndMostDynamicRemovals) {
  WriteRunFolder(root_ / "run");
  ReportOptions options;
  options.thumbnail_width = 200;
  const json data = RunReportData(ReadRunFolder(root_ / "run"), options);
  EXPECT_EQ(data["traj"]["worst"]["timestamp"].get<double>(), 100.0 + 0.1 * kWorstFrame);
  const json& thumbs = data["thumbs"];
  ASSERT_EQ(thumbs.size(), 3u);
  EXPECT_EQ(thumbs[0]["frame"], kWorstFrame);
  EXPECT_NE(thumbs[0]["reason"].get<std::string>().find("worst error"), std::string::npos);
  EXPECT_EQ(thumbs[1]["frame"], kRelocFrame);
  EXPECT_EQ(thumbs[1]["reason"], "relocalised");
  EXPECT_EQ(thumbs[2]["frame"], kDynamicFrame);
  // 40 stage-1 + 1 stage-2 removals.
  EXPECT_EQ(thumbs[2]["reason"], "most dynamic removals (41 points)");
  // The first lost frame (30) is wanted too but has no viz image: the report says so.
  EXPECT_EQ(data["thumbs_note"], "viz/ has no image for frame(s) 30");
  EXPECT_FALSE(data.contains("alignment_note"));
  // Downscaled to the requested width (JPEG in base64: decode through OpenCV).
  const std::string b64 = thumbs[0]["jpeg_b64"];
  std::string bytes;
  int bits = 0, value = 0;
  for (char c : b64) {
    if (c == '=') break;
    const std::string alphabet =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    value = (value << 6) | static_cast<int>(alphabet.find(c));
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      bytes.push_back(static_cast<char>((value >> bits) & 0xFF));
    }
  }
  const cv::Mat thumb = cv::imdecode(std::vector<uint8_t>(bytes.begin(), bytes.end()),
                                     cv::IMREAD_COLOR);
  ASSERT_FALSE(thumb.empty());
  EXPECT_EQ(thumb.cols, 200);
  EXPECT_EQ(thumb.rows, 150);
}

TEST_F(ReportTest, PerFrameSeriesAndCriticalPath) {
  WriteRunFolder(root_ / "run");
  const json data = RunReportData(ReadRunFolder(root_ / "run"), ReportOptions());
  const json& frames = data["frames"];
  ASSERT_EQ(frames["frame"].size(), static_cast<size_t>(kFrames));
  EXPECT_EQ(frames["state"][30], 2);
  EXPECT_EQ(frames["state"][29], 1);
  EXPECT_EQ(frames["relocalised"][kRelocFrame], 1);
  EXPECT_EQ(frames["keyframe"][5], 1);
  EXPECT_EQ(frames["filter"]["removed_stage1"][kDynamicFrame], 40);
  EXPECT_NEAR(frames["depth_scale"][10].get<double>(), 1.1, 1e-12);
  // The metric scale's confidence where a frame reported it, null elsewhere.
  EXPECT_NEAR(frames["scale_sigma"][10].get<double>(), 0.01, 1e-12);
  EXPECT_TRUE(frames["scale_sigma"][0].is_null());
  EXPECT_TRUE(frames["scale_sigma"][30].is_null());  // lost
  EXPECT_EQ(frames["scale_sigma"].size(), static_cast<size_t>(kFrames));
  // The map's scale at its measured keyframes, null elsewhere.
  EXPECT_NEAR(frames["map_scale"][5].get<double>(), 1.2, 1e-12);
  EXPECT_NEAR(frames["map_scale"][10].get<double>(), 1.3, 1e-12);
  EXPECT_TRUE(frames["map_scale"][6].is_null());
  EXPECT_EQ(frames["map_scale"].size(), static_cast<size_t>(kFrames));
  const json& cp = data["critical_path"];
  // Main thread 3 + 1 + (10..12) + 5 = 19..21 ms against the worker's 4 + 2 = 6 ms.
  EXPECT_EQ(cp["critical_branch"], "main");
  EXPECT_EQ(cp["main_bound_frames"], kFrames);
  EXPECT_EQ(cp["dominant_stage"], "tracking");
  EXPECT_DOUBLE_EQ(cp["dominant_median_ms"].get<double>(), 11.0);
  EXPECT_DOUBLE_EQ(cp["main_median_ms"].get<double>(), 20.0);
  EXPECT_DOUBLE_EQ(cp["worker_median_ms"].get<double>(), 6.0);
}

TEST_F(ReportTest, CriticalPathFromTheMediansWithoutPerFrameTimes) {
  WriteRunFolder(root_ / "run");
  json summary = json::parse(ReadTextFile(root_ / "run" / "summary.json"));
  for (json& f : summary["per_frame"]) f.erase("ms");
  summary["timing"] = {{"extraction", {{"median_ms", 8.0}, {"p95_ms", 9.0}}},
                       {"depth", {{"median_ms", 40.0}, {"p95_ms", 50.0}}},
                       {"detection", {{"median_ms", 15.0}, {"p95_ms", 16.0}}},
                       {"filter", {{"median_ms", 1.0}, {"p95_ms", 2.0}}},
                       {"tracking", {{"median_ms", 9.0}, {"p95_ms", 12.0}}},
                       {"local_mapping", {{"median_ms", 2.0}, {"p95_ms", 200.0}}}};
  WriteTextFileAtomic(root_ / "run" / "summary.json", summary.dump());
  const json data = RunReportData(ReadRunFolder(root_ / "run"), ReportOptions());
  EXPECT_TRUE(data["frames"]["ms"].empty());
  const json& cp = data["critical_path"];
  // Worker 40 + 15 = 55 ms against main 8 + 1 + 9 + 2 = 20 ms: depth dominates.
  EXPECT_EQ(cp["from_medians"], true);
  EXPECT_EQ(cp["critical_branch"], "worker");
  EXPECT_EQ(cp["dominant_stage"], "depth");
  EXPECT_DOUBLE_EQ(cp["main_median_ms"].get<double>(), 20.0);
  EXPECT_DOUBLE_EQ(cp["worker_median_ms"].get<double>(), 55.0);
}

// A newer summary says where each stage ran: extraction on the prefetch worker moves there.
TEST_F(ReportTest, CriticalPathPutsStagesOnTheThreadTheSummaryNames) {
  WriteRunFolder(root_ / "run");
  json summary = json::parse(ReadTextFile(root_ / "run" / "summary.json"));
  for (json& f : summary["per_frame"]) f.erase("ms");
  auto stage = [](double median, const char* thread) {
    return json{{"median_ms", median}, {"p95_ms", median}, {"thread", thread}};
  };
  summary["timing"] = {{"decode", stage(3.0, "prefetch")},
                       {"extraction", stage(8.0, "prefetch")},
                       {"keypoint_depth", stage(0.5, "prefetch")},
                       {"depth", stage(0.5, "prefetch")},
                       {"detection", stage(0.0, "prefetch")},
                       {"filter", stage(1.0, "tracking")},
                       {"tracking", stage(7.0, "tracking")},
                       {"local_mapping", stage(2.0, "mapping")},
                       {"tracking_thread", stage(9.0, "tracking")}};
  WriteTextFileAtomic(root_ / "run" / "summary.json", summary.dump());
  const json cp = RunReportData(ReadRunFolder(root_ / "run"), ReportOptions())["critical_path"];
  // Worker 3 + 8 + 0.5 + 0.5 + 0 = 12 ms against main 1 + 7 + 2 = 10 ms.
  EXPECT_EQ(cp["critical_branch"], "worker");
  EXPECT_EQ(cp["dominant_stage"], "extraction");
  EXPECT_DOUBLE_EQ(cp["main_median_ms"].get<double>(), 10.0);
  EXPECT_DOUBLE_EQ(cp["worker_median_ms"].get<double>(), 12.0);
}

TEST_F(ReportTest, SubsamplesTheMapBeyondTheCap) {
  WriteRunFolder(root_ / "run");
  ReportOptions options;
  options.max_map_points = 300;
  const json map = RunReportData(ReadRunFolder(root_ / "run"), options)["map"];
  EXPECT_EQ(map["total"], 1000);
  EXPECT_EQ(map["stride"], 4);
  EXPECT_EQ(map["count"], 250);
  // 250 float triples in base64: 3000 bytes -> 4000 characters.
  EXPECT_EQ(map["xyz_b64"].get<std::string>().size(), 4000u);
}

TEST_F(ReportTest, WithoutGroundTruthVizOrMapItSaysSo) {
  WriteRunFolder(root_ / "run", {.ground_truth = false, .viz = false, .map = false});
  const json data = RunReportData(ReadRunFolder(root_ / "run"), ReportOptions());
  EXPECT_EQ(data["alignment"], "none");
  EXPECT_NE(data["alignment_note"].get<std::string>().find("no ground truth"), std::string::npos);
  EXPECT_FALSE(data["traj"].contains("err"));
  EXPECT_EQ(data["thumbs"].size(), 0u);
  EXPECT_NE(data["thumbs_note"].get<std::string>().find("no viz/"), std::string::npos);
  EXPECT_EQ(data["map"]["count"], 0);
}

TEST_F(ReportTest, ComparesRunsByAte) {
  WriteRunFolder(root_ / "a", {.noise = 0.0});
  WriteRunFolder(root_ / "b", {.noise = 0.05});
  const std::vector<RunFolder> runs = {ReadRunFolder(root_ / "a"), ReadRunFolder(root_ / "b")};
  const json data = ComparisonReportData(runs, {"clean", "noisy"}, ReportOptions());
  EXPECT_EQ(data["kind"], "comparison");
  ASSERT_EQ(data["variants"].size(), 2u);
  EXPECT_EQ(data["variants"][0]["name"], "clean");
  const double clean = data["variants"][0]["ate_rmse_m"];
  const double noisy = data["variants"][1]["ate_rmse_m"];
  EXPECT_GT(clean, 0.01);  // the 0.3 m bump at frame 25
  EXPECT_GT(noisy, clean);
  EXPECT_THROW(ComparisonReportData(runs, {"only one"}, ReportOptions()), std::invalid_argument);

  const fs::path out = WriteComparisonReport({root_ / "a", root_ / "b"}, {}, ReportOptions());
  EXPECT_EQ(out, root_ / "report.html");
  EXPECT_NE(ReadTextFile(out).find("\"kind\":\"comparison\""), std::string::npos);
}

TEST_F(ReportTest, PageInlinesTheLibrariesAndKeepsTheDataInsideItsScript) {
  WriteRunFolder(root_ / "run", {.dataset = "folder:</script><b>x"});
  const fs::path out = WriteRunReport(root_ / "run", ReportOptions());
  EXPECT_EQ(out, root_ / "run" / "report.html");
  const std::string html = ReadTextFile(out);
  EXPECT_NE(html.find("uPlot"), std::string::npos);
  EXPECT_NE(html.find("createREGL"), std::string::npos);
  EXPECT_NE(html.find("Copyright (c) 2016 Mikola Lysenko"), std::string::npos);  // regl's licence
  EXPECT_NE(html.find("folder:\\u003c/script>\\u003cb>x"), std::string::npos);
  EXPECT_EQ(html.find("folder:</script>"), std::string::npos);
  // Deterministic: the same folder gives the same bytes.
  WriteRunReport(root_ / "run", ReportOptions(), root_ / "again.html");
  EXPECT_EQ(ReadTextFile(root_ / "again.html"), html);
  // Nothing fetched at view time.
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);
  EXPECT_EQ(html.find("<script src"), std::string::npos);
}

TEST_F(ReportTest, BadInputNamesTheFile) {
  const fs::path run = root_ / "run";
  auto expect_error = [&](const std::string& fragment) {
    try {
      ReadRunFolder(run);
      RunReportData(ReadRunFolder(run), ReportOptions());
      ADD_FAILURE() << "no error, expected '" << fragment << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expect_error("run");  // no folder
  WriteRunFolder(run);
  fs::remove(run / "summary.json");
  expect_error("summary.json");
  WriteTextFileAtomic(run / "summary.json", "{\"schema\": \"ademono.run/0\", \"per_frame\": []}");
  expect_error("summary.json: schema is \"ademono.run/0\", expected \"ademono.run/1\"");
  WriteTextFileAtomic(run / "summary.json", "{not json");
  expect_error("not valid JSON");
  WriteRunFolder(run);
  json summary = json::parse(ReadTextFile(run / "summary.json"));
  summary["per_frame"][3]["state"] = "flying";
  WriteTextFileAtomic(run / "summary.json", summary.dump());
  expect_error("per_frame[3].state: unknown state 'flying'");
  summary["per_frame"][3]["state"] = "ok";
  summary["per_frame"][4].erase("ms");
  WriteTextFileAtomic(run / "summary.json", summary.dump());
  expect_error("per_frame: 'depth' is missing in some frames");
  WriteRunFolder(run);
  summary = json::parse(ReadTextFile(run / "summary.json"));
  summary["map_scale"]["per_keyframe"][1]["scale"] = "tall";
  WriteTextFileAtomic(run / "summary.json", summary.dump());
  expect_error("summary.json: map_scale: ");
  WriteRunFolder(run);
  WriteTextFileAtomic(run / "map.ply",
                      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                      "property float y\nproperty float z\nend_header\n1 2 3\n4 5\n");
  expect_error("map.ply: vertex 1 is truncated or not a number");
}

TEST(ReadPlyPointsTest, ReadsBinaryLittleEndian) {
  const fs::path path =
      fs::temp_directory_path() / ("ademono_ply_" + std::to_string(::getpid()) + ".ply");
  {
    std::ofstream out(path, std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
           "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
           "property uchar blue\nend_header\n";
    for (int i = 0; i < 2; ++i) {
      const float xyz[3] = {1.5f * i, -2.0f, 3.25f};
      const uint8_t rgb[3] = {255, static_cast<uint8_t>(10 * i), 7};
      out.write(reinterpret_cast<const char*>(xyz), sizeof(xyz));
      out.write(reinterpret_cast<const char*>(rgb), sizeof(rgb));
    }
  }
  const MapCloud cloud = ReadPlyPoints(path);
  fs::remove(path);
  ASSERT_EQ(cloud.xyz.size(), 2u);
  EXPECT_FLOAT_EQ(cloud.xyz[1].x(), 1.5f);
  EXPECT_FLOAT_EQ(cloud.xyz[1].z(), 3.25f);
  EXPECT_EQ(cloud.rgb[1][1], 10);
  EXPECT_EQ(cloud.rgb[0][0], 255);
}

TEST(ReportOptionsTest, FromYamlIsStrict) {
  const ReportOptions o =
      ReportOptions::FromYaml(YAML::Load("{alignment: sim3, max_map_points: 5}"));
  EXPECT_EQ(o.alignment, Alignment::kSim3);
  EXPECT_FALSE(o.sim3_without_metric_scale);  // an alignment asked for is kept
  EXPECT_TRUE(
      ReportOptions::FromYaml(YAML::Load("{max_map_points: 5}")).sim3_without_metric_scale);
  EXPECT_EQ(o.max_map_points, 5);
  EXPECT_THROW(ReportOptions::FromYaml(YAML::Load("{max_points: 5}")), std::invalid_argument);
  EXPECT_THROW(ReportOptions::FromYaml(YAML::Load("{alignment: affine}")), std::invalid_argument);
  EXPECT_THROW(ReportOptions::FromYaml(YAML::Load("{thumbnail_width: 2}")), std::invalid_argument);
}

}  // namespace
}  // namespace ademono
