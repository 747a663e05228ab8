// ONNX Runtime inference speed, ms per 640x480 frame, with 1 and 2 intra-op threads
// (the argument): YOLOX-nano (../shared/models) including letterbox and decoding, and the
// tiny test depth models including resize, normalisation and output resampling.
//   build/<dir>/bench/bench_dnn --benchmark_min_time=2
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>

#include "ademono/depth/onnx_depth.h"
#include "ademono/detect/yolo_detector.h"

namespace {

namespace fs = std::filesystem;
const fs::path kFrame = ADEMONO_SHARED_DIR "/data/7scenes-seq-a/frame-000000.color.jpg";
const fs::path kYolox = ADEMONO_SHARED_DIR "/models/yolox_nano.onnx";
const fs::path kModels = ADEMONO_SOURCE_DIR "/tests/data/models";

cv::Mat LoadFrame() {
  cv::Mat image = cv::imread(kFrame.string(), cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error("cannot read " + kFrame.string());
  return image;
}

ademono::Camera SevenScenesCamera() { return ademono::Camera::Pinhole(640, 480, 585, 320, 240); }

void BM_YoloxNano640x480(benchmark::State& state) {
  const cv::Mat image = LoadFrame();
  ademono::DetectorOptions options;
  options.num_threads = static_cast<int>(state.range(0));
  ademono::YoloDetector detector(kYolox, ademono::YoloArch::kAuto, options);
  for (auto _ : state) {
    auto detections = detector.DetectImage(image);
    benchmark::DoNotOptimize(detections.data());
  }
  state.SetLabel(detector.Session().Provider());
}
BENCHMARK(BM_YoloxNano640x480)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void RunDepth(benchmark::State& state, const fs::path& model, const std::optional<fs::path>& spec) {
  const cv::Mat image = LoadFrame();
  ademono::OrtSessionOptions options;
  options.intra_op_threads = static_cast<int>(state.range(0));
  ademono::OnnxDepthProvider provider(model, spec, options);
  const ademono::Camera camera = SevenScenesCamera();
  for (auto _ : state) {
    cv::Mat depth = provider.DepthFromImage(image, camera);
    benchmark::DoNotOptimize(depth.data);
  }
}

// Fixed 64x48 input: mostly resize, normalisation and upsampling back to 640x480.
void BM_TestDepthFixed64x48(benchmark::State& state) {
  RunDepth(state, kModels / "depth_metric.onnx", std::nullopt);
}
BENCHMARK(BM_TestDepthFixed64x48)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// Dynamic model at the native 640x480 (multiple of 32, no resize): full-size tensors through
// ONNX Runtime.
void BM_TestDepthDynamic640x480(benchmark::State& state) {
  const fs::path spec =
      fs::temp_directory_path() / ("ademono_bench_dnn_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(spec) << "input:\n  resize: multiple\n  multiple_of: 32\n  pad: bottom_right\n"
                         "output:\n  kind: metric\n";
  RunDepth(state, kModels / "depth_dynamic.onnx", spec);
  fs::remove(spec);
}
BENCHMARK(BM_TestDepthDynamic640x480)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
