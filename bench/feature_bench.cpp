// ORB extraction and matching speed on a real 640x480 frame (7-Scenes). Run single-threaded to
// match the "one core" budget: OpenCV's internal threads are disabled in main().
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <Eigen/LU>
#include <cstdio>
#include <fstream>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "ademono/feature/grid_fast.h"
#include "ademono/feature/matching.h"
#include "ademono/feature/orb_extractor.h"
#include "ademono/filter/feature_filter.h"

namespace {

const char* kFrame0 = ADEMONO_SHARED_DIR "/data/7scenes-seq-a/frame-000000.color.jpg";
const char* kFrame1 = ADEMONO_SHARED_DIR "/data/7scenes-seq-a/frame-000001.color.jpg";

cv::Mat LoadGrey(const char* path) {
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw std::runtime_error(std::string("cannot read ") + path);
  return image;
}

void BM_OrbExtract640x480(benchmark::State& state) {
  const cv::Mat image = LoadGrey(kFrame0);
  ademono::OrbOptions options;
  options.num_features = static_cast<int>(state.range(0));
  const ademono::OrbExtractor extractor(options);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  for (auto _ : state) {
    extractor.Extract(image, keypoints, descriptors);
    benchmark::DoNotOptimize(descriptors.data);
  }
  state.counters["keypoints"] = static_cast<double>(keypoints.size());
}
BENCHMARK(BM_OrbExtract640x480)->Arg(1000)->Arg(2000)->Unit(benchmark::kMillisecond);

// The extractor's gridded FAST over a whole 8-level pyramid of a 640x480 frame: Arg 0 is one
// cv::FAST call per 30-px cell (the reference), Arg 1 one vectorised pass per level and per-cell
// suppression (DetectGridFast, what the extractor uses; same keypoints).
void BM_GridFast(benchmark::State& state) {
  std::vector<cv::Mat> levels{LoadGrey(kFrame0)};
  for (int l = 1; l < 8; ++l) {
    cv::Mat next;
    cv::resize(levels.back(), next, cv::Size(), 1 / 1.2, 1 / 1.2, cv::INTER_LINEAR);
    levels.push_back(next);
  }
  std::vector<ademono::FastGrid> grids;
  for (const cv::Mat& level : levels) {
    ademono::FastGrid g;
    g.min_x = 16, g.min_y = 16, g.max_x = level.cols - 16, g.max_y = level.rows - 16;
    const int width = g.max_x - g.min_x, height = g.max_y - g.min_y;
    g.num_cols = std::max(1, width / 30), g.num_rows = std::max(1, height / 30);
    g.cell_w = (width + g.num_cols - 1) / g.num_cols;
    g.cell_h = (height + g.num_rows - 1) / g.num_rows;
    grids.push_back(g);
  }
  size_t count = 0;
  for (auto _ : state) {
    count = 0;
    for (size_t l = 0; l < levels.size(); ++l) {
      count += (state.range(0) == 0 ? ademono::DetectGridFastReference(levels[l], grids[l], 20, 7)
                                    : ademono::DetectGridFast(levels[l], grids[l], 20, 7))
                   .size();
    }
  }
  state.counters["corners"] = static_cast<double>(count);
}
BENCHMARK(BM_GridFast)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_MatchBruteForce(benchmark::State& state) {
  const ademono::OrbExtractor extractor{ademono::OrbOptions{}};
  std::vector<cv::KeyPoint> k0, k1;
  cv::Mat d0, d1;
  extractor.Extract(LoadGrey(kFrame0), k0, d0);
  extractor.Extract(LoadGrey(kFrame1), k1, d1);
  size_t matches = 0;
  for (auto _ : state) matches = ademono::MatchBruteForce(d1, d0).size();
  state.counters["matches"] = static_cast<double>(matches);
}
BENCHMARK(BM_MatchBruteForce)->Unit(benchmark::kMillisecond);

// Match quality on real frames: frame s against frame s + `gap` (7-Scenes, ten start frames),
// brute force with the ratio test. A match counts as correct when frame 0's keypoint, lifted with
// its Kinect depth and moved by the ground-truth relative pose, lands within 8 px of the matched
// keypoint (the depth is not registered to the colour image, hence the loose bound). Reports the
// same figure for OpenCV's own ORB (same feature count) as a reference. The timed part is the
// matching.
Eigen::Matrix4d LoadPose(int frame) {
  char path[512];
  std::snprintf(path, sizeof(path), "%s/data/7scenes-seq-a/frame-%06d.pose.txt", ADEMONO_SHARED_DIR,
                frame);
  std::ifstream in(path);
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i)
    if (!(in >> m(i / 4, i % 4))) throw std::runtime_error(std::string("cannot read ") + path);
  return m;
}

std::string FramePath(int frame, const char* kind) {
  char path[512];
  std::snprintf(path, sizeof(path), "%s/data/7scenes-seq-a/frame-%06d.%s", ADEMONO_SHARED_DIR,
                frame, kind);
  return path;
}

double CorrectMatchRatio(const std::vector<cv::KeyPoint>& k0, const std::vector<cv::KeyPoint>& k1,
                         const std::vector<cv::DMatch>& matches, const cv::Mat& depth0,
                         const Eigen::Matrix4d& cam1_from_cam0, int* num_checked) {
  const double f = 585, c_x = 320, c_y = 240;
  int checked = 0, correct = 0;
  for (const cv::DMatch& m : matches) {
    const cv::Point2f p0 = k0[m.queryIdx].pt;
    const uint16_t mm = depth0.at<uint16_t>(cvRound(p0.y), cvRound(p0.x));
    if (mm == 0 || mm == 65535) continue;
    const double z = mm / 1000.0;
    const Eigen::Vector4d x0((p0.x - c_x) / f * z, (p0.y - c_y) / f * z, z, 1.0);
    const Eigen::Vector4d x1 = cam1_from_cam0 * x0;
    if (x1.z() <= 0) continue;
    ++checked;
    const cv::Point2f proj(static_cast<float>(f * x1.x() / x1.z() + c_x),
                           static_cast<float>(f * x1.y() / x1.z() + c_y));
    if (cv::norm(proj - k1[m.trainIdx].pt) < 8.0) ++correct;
  }
  *num_checked = checked;
  return checked > 0 ? static_cast<double>(correct) / checked : 0.0;
}

void BM_MatchQuality(benchmark::State& state) {
  const int gap = static_cast<int>(state.range(0));
  const ademono::OrbExtractor extractor{ademono::OrbOptions{}};
  const cv::Ptr<cv::ORB> orb = cv::ORB::create(1000);
  // Pairs (s, s + gap) for s = 0, 50, ..., 450: the pooled fraction of correct matches.
  double ours_matches = 0, ours_correct = 0, ours_checked = 0;
  double cv_matches = 0, cv_correct = 0, cv_checked = 0;
  cv::Mat first_d0, first_d1;
  for (int start = 0; start < 500; start += 50) {
    const cv::Mat img0 = LoadGrey(FramePath(start, "color.jpg").c_str());
    const cv::Mat img1 = LoadGrey(FramePath(start + gap, "color.jpg").c_str());
    const cv::Mat depth0 = cv::imread(FramePath(start, "depth.png"), cv::IMREAD_UNCHANGED);
    const Eigen::Matrix4d cam1_from_cam0 = LoadPose(start + gap).inverse() * LoadPose(start);
    std::vector<cv::KeyPoint> k0, k1;
    cv::Mat d0, d1;
    extractor.Extract(img0, k0, d0);
    extractor.Extract(img1, k1, d1);
    if (start == 0) {
      first_d0 = d0;
      first_d1 = d1;
    }
    const std::vector<cv::DMatch> matches = ademono::MatchBruteForce(d0, d1);
    int checked = 0;
    const double ratio = CorrectMatchRatio(k0, k1, matches, depth0, cam1_from_cam0, &checked);
    ours_matches += static_cast<double>(matches.size());
    ours_correct += ratio * checked;
    ours_checked += checked;
    // Reference: OpenCV's ORB (Harris ranking, no quadtree), same count, same matcher.
    std::vector<cv::KeyPoint> o0, o1;
    cv::Mat e0, e1;
    orb->detectAndCompute(img0, cv::noArray(), o0, e0);
    orb->detectAndCompute(img1, cv::noArray(), o1, e1);
    const std::vector<cv::DMatch> om = ademono::MatchBruteForce(e0, e1);
    const double cv_ratio = CorrectMatchRatio(o0, o1, om, depth0, cam1_from_cam0, &checked);
    cv_matches += static_cast<double>(om.size());
    cv_correct += cv_ratio * checked;
    cv_checked += checked;
  }
  for (auto _ : state)
    benchmark::DoNotOptimize(ademono::MatchBruteForce(first_d0, first_d1).data());
  state.counters["matches_per_pair"] = ours_matches / 10;
  state.counters["correct"] = ours_checked > 0 ? ours_correct / ours_checked : 0;
  state.counters["cv_matches_per_pair"] = cv_matches / 10;
  state.counters["cv_correct"] = cv_checked > 0 ? cv_correct / cv_checked : 0;
}
BENCHMARK(BM_MatchQuality)->Arg(1)->Arg(5)->Arg(30)->Unit(benchmark::kMillisecond);

// The three filters on a real frame: 1000 ORB keypoints with sensor depth, one large "dynamic"
// box over the centre of the image (7-Scenes is static, so the box exercises both stages on
// static points) and the previous frame's features with camera and world points from depth (stage 1
// fits the camera motion to the background).
void BM_FeatureFilter(benchmark::State& state) {
  const ademono::OrbExtractor extractor{ademono::OrbOptions{}};
  const ademono::Camera camera = ademono::Camera::Pinhole(640, 480, 585, 320, 240);
  auto load_depths = [&](const char* depth_path, const std::vector<cv::KeyPoint>& kps) {
    const cv::Mat depth = cv::imread(depth_path, cv::IMREAD_UNCHANGED);
    if (depth.empty()) throw std::runtime_error(std::string("cannot read ") + depth_path);
    std::vector<float> d(kps.size(), 0.f);
    for (size_t i = 0; i < kps.size(); ++i) {
      const uint16_t mm = depth.at<uint16_t>(cvRound(kps[i].pt.y), cvRound(kps[i].pt.x));
      d[i] = (mm == 0 || mm == 65535) ? 0.f : mm / 1000.f;
    }
    return d;
  };
  std::vector<cv::KeyPoint> k0, k1;
  cv::Mat d0, d1;
  extractor.Extract(LoadGrey(kFrame0), k0, d0);
  extractor.Extract(LoadGrey(kFrame1), k1, d1);
  const std::vector<float> depth0 =
      load_depths(ADEMONO_SHARED_DIR "/data/7scenes-seq-a/frame-000000.depth.png", k0);
  const std::vector<float> depth1 =
      load_depths(ADEMONO_SHARED_DIR "/data/7scenes-seq-a/frame-000001.depth.png", k1);
  ademono::PreviousFrameFeatures previous;
  previous.keypoints = k0;
  previous.descriptors = d0;
  for (size_t i = 0; i < k0.size(); ++i) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    previous.points_cam.push_back(
        depth0[i] > 0 ? camera.Unproject(Eigen::Vector2d(k0[i].pt.x, k0[i].pt.y), depth0[i])
                      : Eigen::Vector3d(nan, nan, nan));
  }
  previous.points_world = previous.points_cam;  // frame 0 taken as the world frame
  ademono::Detection box;
  box.class_id = 0;
  box.class_name = "person";
  box.box = cv::Rect2f(160, 120, 320, 240);
  const std::vector<ademono::Detection> detections{box};
  ademono::FilterOptions options;
  options.z_th_m = 2.0;  // indoor scene: make the distant filter draw too
  options.dynamic.stage1_motion_compensation = state.range(0) != 0;  // 0: the paper's stage 1
  ademono::FeatureFilter filter(options);
  ademono::FilterInput input;
  input.camera = &camera;
  input.keypoints = &k1;
  input.descriptors = &d1;
  input.depths = &depth1;
  input.detections = &detections;
  input.previous = &previous;
  input.predicted_cam_from_world = ademono::Rigid3d::Identity();
  ademono::FilterStats stats;
  for (auto _ : state) benchmark::DoNotOptimize(filter.Apply(input, &stats).data());
  state.counters["keypoints"] = static_cast<double>(k1.size());
  state.counters["kept"] = stats.kept;
  state.counters["enh"] = stats.removed_enhancement;
  state.counters["stage1"] = stats.removed_stage1;
  state.counters["stage2"] = stats.removed_stage2;
  state.counters["distant"] = stats.removed_distant;
}
BENCHMARK(BM_FeatureFilter)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  cv::setNumThreads(1);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
