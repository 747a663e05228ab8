// ORB extraction and matching speed on a real 640x480 frame (7-Scenes). Run single-threaded to
// match the "one core" budget: OpenCV's internal threads are disabled in main().
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "ademono/feature/matching.h"
#include "ademono/feature/orb_extractor.h"

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

}  // namespace

int main(int argc, char** argv) {
  cv::setNumThreads(1);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
