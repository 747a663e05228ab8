// Place recognition: query time against map size (synthetic ORB-like descriptors, 1,000 per
// keyframe, up to 4,000 keyframes) for the KeyFrameDatabase (bit-sampling bag of words + TF-IDF)
// and two alternatives it was chosen over: OpenCV FLANN LSH with keyframe voting (the index must
// be rebuilt when keyframes are added: build time reported) and exact brute-force voting.
// BM_RecallSeqA: recall of the right keyframe on 7-Scenes seq-a (keyframes every 10th frame of
// 0-299, queries every 10th of 300-599; "right" = the keyframe nearest in ground-truth pose).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/flann.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>

#include "ademono/feature/orb_extractor.h"
#include "ademono/place/keyframe_database.h"

namespace {

// Keyframe k shares its first 300 "features" with keyframe k - 1 (perturbed): a trajectory.
std::vector<cv::Mat> SyntheticKeyFrames(int count) {
  std::vector<cv::Mat> out;
  cv::RNG rng(7);
  for (int k = 0; k < count; ++k) {
    cv::Mat d(1000, 32, CV_8UC1);
    rng.fill(d, cv::RNG::UNIFORM, 0, 256);
    if (k > 0) {
      out.back().rowRange(700, 1000).copyTo(d.rowRange(0, 300));
      for (int r = 0; r < 300; ++r) d.at<uint8_t>(r, rng.uniform(0, 32)) ^= 0x11;
    }
    out.push_back(d);
  }
  return out;
}

void BM_QueryKeyFrameDatabase(benchmark::State& state) {
  const auto keyframes = SyntheticKeyFrames(static_cast<int>(state.range(0)));
  ademono::KeyFrameDatabase db;
  for (size_t i = 0; i < keyframes.size(); ++i) db.Add(i, keyframes[i]);
  size_t q = 0, hits = 0, queries = 0;
  for (auto _ : state) {
    const auto c = db.Query(keyframes[q], 10);
    hits += (!c.empty() && c[0].keyframe_id == q) ? 1 : 0;
    ++queries;
    q = (q + 97) % keyframes.size();
  }
  state.counters["top1"] = static_cast<double>(hits) / static_cast<double>(queries);
}
BENCHMARK(BM_QueryKeyFrameDatabase)->Arg(100)->Arg(500)->Arg(1000)->Arg(2000)->Arg(4000)
    ->Unit(benchmark::kMillisecond);

void BM_AddKeyFrameDatabase(benchmark::State& state) {
  const auto keyframes = SyntheticKeyFrames(200);
  for (auto _ : state) {
    ademono::KeyFrameDatabase db;
    for (size_t i = 0; i < keyframes.size(); ++i) db.Add(i, keyframes[i]);
    benchmark::DoNotOptimize(db.Size());
  }
  state.SetItemsProcessed(state.iterations() * 200);
}
BENCHMARK(BM_AddKeyFrameDatabase)->Unit(benchmark::kMillisecond);

// FLANN LSH over every descriptor of the map, 2 nearest neighbours per query descriptor vote for
// their keyframes.
void BM_QueryFlannLshVoting(benchmark::State& state) {
  const auto keyframes = SyntheticKeyFrames(static_cast<int>(state.range(0)));
  cv::Mat all;
  std::vector<int> owner;
  for (size_t i = 0; i < keyframes.size(); ++i) {
    all.push_back(keyframes[i]);
    owner.insert(owner.end(), keyframes[i].rows, static_cast<int>(i));
  }
  const auto t0 = std::chrono::steady_clock::now();
  cv::flann::Index index(all, cv::flann::LshIndexParams(6, 16, 1), cvflann::FLANN_DIST_HAMMING);
  const double build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  size_t q = 0;
  for (auto _ : state) {
    cv::Mat indices, dists;
    index.knnSearch(keyframes[q], indices, dists, 2, cv::flann::SearchParams(32));
    std::map<int, int> votes;
    for (int r = 0; r < indices.rows; ++r)
      for (int c = 0; c < indices.cols; ++c) {
        const int i = indices.at<int>(r, c);
        if (i >= 0 && i < static_cast<int>(owner.size())) ++votes[owner[i]];
      }
    benchmark::DoNotOptimize(votes.size());
    q = (q + 97) % keyframes.size();
  }
  state.counters["build_ms"] = build_ms;
}
BENCHMARK(BM_QueryFlannLshVoting)->Arg(100)->Arg(500)->Arg(1000)->Arg(2000)
    ->Unit(benchmark::kMillisecond);

void BM_QueryBruteForceVoting(benchmark::State& state) {
  const auto keyframes = SyntheticKeyFrames(static_cast<int>(state.range(0)));
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  size_t q = 0;
  for (auto _ : state) {
    std::vector<int> votes(keyframes.size(), 0);
    for (size_t k = 0; k < keyframes.size(); ++k) {
      std::vector<cv::DMatch> m;
      matcher.match(keyframes[q], keyframes[k], m);
      for (const auto& x : m) votes[k] += x.distance < 50 ? 1 : 0;
    }
    benchmark::DoNotOptimize(votes.data());
    q = (q + 97) % keyframes.size();
  }
}
BENCHMARK(BM_QueryBruteForceVoting)->Arg(100)->Arg(500)->Unit(benchmark::kMillisecond);

// --- recall on real revisits -------------------------------------------------------------

Eigen::Matrix4d ReadPose(int index) {
  char path[512];
  std::snprintf(path, sizeof(path), "%s/data/7scenes-seq-a/frame-%06d.pose.txt",
                ADEMONO_SHARED_DIR, index);
  std::ifstream in(path);
  if (!in) throw std::runtime_error(std::string("cannot read ") + path);
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) in >> m(r, c);
  return m;
}

cv::Mat Descriptors(int index) {
  char path[512];
  std::snprintf(path, sizeof(path), "%s/data/7scenes-seq-a/frame-%06d.color.jpg",
                ADEMONO_SHARED_DIR, index);
  const cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw std::runtime_error(std::string("cannot read ") + path);
  static const ademono::OrbExtractor extractor{ademono::OrbOptions{}};
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  extractor.Extract(image, keypoints, descriptors);
  return descriptors;
}

// Pose distance: metres + 0.5 m per radian of rotation.
double PoseDistance(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  const double dt = (a.block<3, 1>(0, 3) - b.block<3, 1>(0, 3)).norm();
  const Eigen::Matrix3d r = a.block<3, 3>(0, 0).transpose() * b.block<3, 3>(0, 0);
  const double angle = Eigen::AngleAxisd(r).angle();
  return dt + 0.5 * angle;
}

// Candidates of the three methods for one query: the KeyFrameDatabase, FLANN LSH with keyframe
// voting, exact brute-force voting (matches under 50 bits).
enum Method { kDatabase = 0, kFlannLsh = 1, kBruteForce = 2 };

std::vector<uint64_t> Ranked(std::vector<std::pair<double, uint64_t>> scored, size_t n) {
  std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  std::vector<uint64_t> ids;
  for (size_t i = 0; i < scored.size() && i < n; ++i) ids.push_back(scored[i].second);
  return ids;
}

void BM_RecallSeqA(benchmark::State& state) {
  const int method = static_cast<int>(state.range(0));
  ademono::KeyFrameDatabaseOptions options;
  if (state.range(1) > 0) options.bits_per_table = static_cast<int>(state.range(1));
  if (state.range(2) > 0) options.num_tables = static_cast<int>(state.range(2));
  std::vector<int> kf_frames, query_frames;
  for (int i = 0; i < 300; i += 10) kf_frames.push_back(i);
  for (int i = 300; i < 600; i += 5) query_frames.push_back(i);
  static std::vector<cv::Mat> kf_desc, q_desc;
  static std::vector<Eigen::Matrix4d> kf_pose, q_pose;
  if (kf_desc.empty()) {
    for (int i : kf_frames) kf_desc.push_back(Descriptors(i)), kf_pose.push_back(ReadPose(i));
    for (int i : query_frames) q_desc.push_back(Descriptors(i)), q_pose.push_back(ReadPose(i));
  }
  double recall1 = 0, recall5 = 0, query_ms = 0;
  for (auto _ : state) {
    ademono::KeyFrameDatabase db(options);
    cv::Mat all;
    std::vector<uint64_t> owner;
    for (size_t k = 0; k < kf_desc.size(); ++k) {
      db.Add(k, kf_desc[k]);
      all.push_back(kf_desc[k]);
      owner.insert(owner.end(), kf_desc[k].rows, k);
    }
    cv::flann::Index lsh(all, cv::flann::LshIndexParams(6, 16, 1), cvflann::FLANN_DIST_HAMMING);
    cv::BFMatcher bf(cv::NORM_HAMMING);
    int hit1 = 0, hit5 = 0, counted = 0;
    double total_ms = 0;
    for (size_t q = 0; q < q_desc.size(); ++q) {
      // Acceptable answers: keyframes within 0.15 of the best pose distance (a revisit: <= 1).
      double best = 1e9;
      for (const auto& p : kf_pose) best = std::min(best, PoseDistance(p, q_pose[q]));
      if (best > 1.0) continue;
      ++counted;
      const auto t0 = std::chrono::steady_clock::now();
      std::vector<uint64_t> ids;
      if (method == kDatabase) {
        for (const auto& c : db.Query(q_desc[q], 5)) ids.push_back(c.keyframe_id);
      } else if (method == kFlannLsh) {
        cv::Mat indices, dists;
        lsh.knnSearch(q_desc[q], indices, dists, 2, cv::flann::SearchParams(32));
        std::map<uint64_t, double> votes;
        for (int r = 0; r < indices.rows; ++r)
          for (int c = 0; c < indices.cols; ++c) {
            const int i = indices.at<int>(r, c);
            if (i >= 0 && i < static_cast<int>(owner.size()) && dists.at<int>(r, c) < 50)
              votes[owner[i]] += 1;
          }
        std::vector<std::pair<double, uint64_t>> scored;
        for (const auto& [id, v] : votes) scored.emplace_back(v, id);
        ids = Ranked(scored, 5);
      } else {
        std::vector<std::pair<double, uint64_t>> scored;
        for (size_t k = 0; k < kf_desc.size(); ++k) {
          std::vector<cv::DMatch> m;
          bf.match(q_desc[q], kf_desc[k], m);
          int good = 0;
          for (const auto& x : m) good += x.distance < 50 ? 1 : 0;
          scored.emplace_back(good, k);
        }
        ids = Ranked(scored, 5);
      }
      total_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                      .count();
      for (size_t i = 0; i < ids.size(); ++i) {
        if (PoseDistance(kf_pose[ids[i]], q_pose[q]) <= best + 0.15) {
          if (i == 0) ++hit1;
          ++hit5;
          break;
        }
      }
    }
    recall1 = counted ? static_cast<double>(hit1) / counted : 0;
    recall5 = counted ? static_cast<double>(hit5) / counted : 0;
    query_ms = counted ? total_ms / counted : 0;
    state.counters["queries"] = counted;
  }
  state.counters["recall1"] = recall1;
  state.counters["recall5"] = recall5;
  state.counters["query_ms"] = query_ms;
}
// Args: method (0 database, 1 FLANN LSH voting, 2 brute-force voting), bits, tables.
BENCHMARK(BM_RecallSeqA)->Args({0, 10, 4})->Args({0, 12, 4})->Args({0, 14, 4})->Args({0, 16, 4})
    ->Args({0, 14, 8})->Args({1, 0, 0})->Args({2, 0, 0})->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  cv::setNumThreads(1);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
