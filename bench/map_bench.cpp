// Map files: save (records -> bytes -> atomic file with fsync), load (file -> checked records)
// and restore (records -> live map with features, covisibility and the keyframe database) time,
// and file size, for maps of 250 / 1,000 / 2,000 synthetic keyframes shaped like 7-Scenes ones
// (1,000 keypoints with depth, 50 points created per keyframe, each seen by 4 keyframes, 10
// covisibility edges). The 7-Scenes map of frames 0-299 (115 keyframes, 5,775 points) is
// 6.6 MB: about 57 KB per keyframe, as here.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <opencv2/core.hpp>

#include "ademono/slam/map_io.h"

namespace {

ademono::MapFileData SyntheticMap(int num_keyframes) {
  ademono::MapFileData d;
  d.camera.width = 640;
  d.camera.height = 480;
  d.camera.fx = d.camera.fy = 585;
  d.camera.cx = 320;
  d.camera.cy = 240;
  d.options_yaml = "orb:\n  num_features: 1000\n";
  cv::RNG rng(3);
  constexpr int kKeypoints = 1000, kNewPoints = 50, kViews = 4;
  for (int k = 0; k < num_keyframes; ++k) {
    ademono::MapKeyFrameRecord r;
    r.id = r.frame_id = r.index = static_cast<uint64_t>(k);
    r.timestamp = k / 30.0;
    r.cam_from_world = {1, 0, 0, 0.01 * k, 0, 1, 0, 0, 0, 0, 1, 0};
    for (int i = 0; i < kKeypoints; ++i) {
      r.keypoints.push_back({rng.uniform(0.f, 640.f), rng.uniform(0.f, 480.f), 31.f,
                             rng.uniform(0.f, 360.f), 1e-3f, rng.uniform(0, 8)});
      r.depth.push_back(rng.uniform(0.5f, 4.f));
    }
    r.descriptors.resize(32 * kKeypoints);
    rng.fill(cv::Mat(1, static_cast<int>(r.descriptors.size()), CV_8UC1, r.descriptors.data()),
             cv::RNG::UNIFORM, 0, 256);
    r.bf = 0.08 * 585;
    r.close_depth = 3.2f;
    r.parent = k > 0 ? k - 1 : -1;
    for (int j = std::max(0, k - 5); j < std::min(num_keyframes, k + 6); ++j)
      if (j != k) r.connections.emplace_back(static_cast<uint64_t>(j), 60);
    d.keyframes.push_back(std::move(r));
  }
  uint64_t id = 0;
  for (int k = 0; k + kViews <= num_keyframes; ++k) {
    for (int n = 0; n < kNewPoints; ++n) {
      ademono::MapPointRecord p;
      p.id = id++;
      p.position = {rng.uniform(-2., 2.), rng.uniform(-2., 2.), rng.uniform(0.5, 4.)};
      p.normal = {0, 0, 1};
      p.min_distance = 0.5f;
      p.max_distance = 5.f;
      p.reference = p.first_keyframe_id = static_cast<uint64_t>(k);
      // Keypoint slot n + 50 * view of keyframe k + view: unique per keyframe.
      for (int v = 0; v < kViews; ++v)
        p.observations.emplace_back(static_cast<uint64_t>(k + v),
                                    static_cast<uint32_t>(n + kNewPoints * v));
      d.points.push_back(std::move(p));
    }
  }
  d.next_keyframe_id = static_cast<uint64_t>(num_keyframes);
  d.next_point_id = id;
  return d;
}

std::filesystem::path BenchFile() {
  return std::filesystem::temp_directory_path() / "ademono_map_bench.map";
}

void BM_MapSave(benchmark::State& state) {
  const auto data = SyntheticMap(static_cast<int>(state.range(0)));
  for (auto _ : state) ademono::SaveMapFile(BenchFile(), data);
  const double bytes = static_cast<double>(std::filesystem::file_size(BenchFile()));
  state.counters["file_MB"] = bytes / 1e6;
  state.counters["MB_per_1000_keyframes"] = bytes / 1e6 * 1000.0 / state.range(0);
}
BENCHMARK(BM_MapSave)->Arg(250)->Arg(1000)->Arg(2000)->Unit(benchmark::kMillisecond);

void BM_MapLoad(benchmark::State& state) {
  ademono::SaveMapFile(BenchFile(), SyntheticMap(static_cast<int>(state.range(0))));
  for (auto _ : state) benchmark::DoNotOptimize(ademono::LoadMapFile(BenchFile()).points.size());
}
BENCHMARK(BM_MapLoad)->Arg(250)->Arg(1000)->Arg(2000)->Unit(benchmark::kMillisecond);

void BM_MapRestore(benchmark::State& state) {
  const auto data = SyntheticMap(static_cast<int>(state.range(0)));
  const auto pyramid =
      std::make_shared<ademono::ScalePyramid>(ademono::ScalePyramid::Make(8, 1.2f));
  for (auto _ : state) {
    ademono::KeyFrameDatabase database;
    ademono::Map map;
    map.SetKeyFrameDatabase(&database);
    ademono::MutexLock lock(map.mutex);
    ademono::RestoreMap(data, pyramid, map);
    benchmark::DoNotOptimize(map.NumMapPoints());
  }
}
BENCHMARK(BM_MapRestore)->Arg(250)->Arg(1000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
