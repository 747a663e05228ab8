// `ademono infer`: run the depth model and/or the detector over a dataset once and cache the
// results, so `--depth cache:DIR/depth` and `--detector cache:DIR/detections.jsonl` replay them:
//   DIR/depth/<frame name>.tiff  float32 metres as the network gave them (--depth-format tiff, the
//                                default: a replay reproduces a run with the network to the bit)
//   DIR/depth/<frame name>.png   uint16 millimetres, 0 = invalid (--depth-format png: what TUM-style
//                                tools read; rounding to the millimetre moves a run's figures)
//   DIR/detections.jsonl         detections per frame (perception/detection_io.h)
// Everything is written into a staging folder beside DIR and moved into place at the end, so a
// failed run leaves no partial cache.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <limits>

#include "ademono/core/error.h"
#include "ademono/depth/depth_factory.h"
#include "ademono/depth/onnx_depth.h"
#include "ademono/detect/detector_factory.h"
#include "ademono/io/sequence.h"
#include "ademono/perception/detection_io.h"
#include "command.h"

namespace fs = std::filesystem;

namespace {

struct InferArgs {
  std::string dataset;
  std::string camera;
  std::string depth_model;
  std::string detector;
  std::string frames;
  std::string classes = "dynamic";
  float score = 0.3f;
  float nms = 0.45f;
  int threads = 1;
  std::string depth_format = "tiff";
  std::string out;
};

// "START:END", END exclusive, either may be empty.
void ParseFrames(const std::string& text, size_t* start, size_t* end) {
  const size_t colon = text.find(':');
  auto parse = [&](const std::string& part, size_t* value) {
    if (part.empty()) return true;
    if (part.size() > 12 ||
        !std::all_of(part.begin(), part.end(), [](unsigned char c) { return std::isdigit(c); })) {
      return false;
    }
    *value = std::stoull(part);
    return true;
  };
  if (colon == std::string::npos || !parse(text.substr(0, colon), start) ||
      !parse(text.substr(colon + 1), end)) {
    throw ademono::InputError("--frames '" + text + "': expected START:END (either may be empty)");
  }
  if (*end <= *start) {
    throw ademono::InputError("--frames '" + text + "': END must be greater than START");
  }
}

// Removes the staging folder unless released.
class StagingDir {
 public:
  explicit StagingDir(fs::path path) : path_(std::move(path)) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~StagingDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& Path() const { return path_; }

 private:
  fs::path path_;
};

int RunInfer(const InferArgs& args) {
  if (args.depth_model.empty() && args.detector.empty()) {
    throw ademono::InputError("nothing to do: give --depth-model and/or --detector");
  }
  std::optional<fs::path> camera_yaml;
  if (!args.camera.empty()) camera_yaml = args.camera;
  auto sequence = ademono::OpenSequence(args.dataset, camera_yaml);
  size_t start = 0, end = std::numeric_limits<size_t>::max();
  if (!args.frames.empty()) ParseFrames(args.frames, &start, &end);
  if (start >= sequence->Size()) {
    throw ademono::InputError(fmt::format("--frames '{}': the sequence has only {} frames",
                                          args.frames, sequence->Size()));
  }
  end = std::min(end, sequence->Size());

  std::unique_ptr<ademono::DepthProvider> depth;
  if (!args.depth_model.empty()) {
    ademono::DepthFactoryContext context;
    context.sequence = sequence.get();
    context.num_threads = args.threads;
    depth = ademono::MakeDepthProvider(args.depth_model, context);
  }
  std::unique_ptr<ademono::Detector> detector;
  if (!args.detector.empty()) {
    ademono::DetectorOptions options;
    options.score_threshold = args.score;
    options.nms_iou = args.nms;
    options.class_ids = ademono::ParseClassList(args.classes);
    options.num_threads = args.threads;
    detector = ademono::MakeDetector(args.detector, options);
  }

  fs::path out = fs::absolute(args.out).lexically_normal();
  if (out.filename().empty()) out = out.parent_path();
  // Staged beside DIR (same file system, so the final moves are renames); DIR itself is only
  // created once everything succeeded.
  StagingDir staging(out.parent_path() /
                     fmt::format(".{}.infer.tmp.{}", out.filename().string(), ::getpid()));
  if (depth) fs::create_directories(staging.Path() / "depth");
  std::vector<ademono::FrameDetections> all_detections;
  double depth_ms = 0.0, detect_ms = 0.0;
  for (size_t i = start; i < end; ++i) {
    const ademono::FrameData frame = sequence->Load(i);
    if (frame.name.empty()) {
      throw ademono::InputError(fmt::format("frame {} of {} has no name", i, args.dataset));
    }
    if (depth) {
      const auto t0 = std::chrono::steady_clock::now();
      const cv::Mat map = depth->Depth(frame, sequence->GetCamera());
      depth_ms +=
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      ademono::WriteDepthMap(staging.Path() / "depth" / (frame.name + "." + args.depth_format), map);
    }
    if (detector) {
      const auto t0 = std::chrono::steady_clock::now();
      ademono::FrameDetections entry;
      entry.frame = frame.index;
      entry.timestamp = frame.timestamp;
      entry.name = frame.name;
      entry.detections = detector->Detect(frame);
      detect_ms +=
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      all_detections.push_back(std::move(entry));
    }
    if ((i - start + 1) % 50 == 0) {
      std::cerr << fmt::format("ademono infer: {}/{} frames\n", i - start + 1, end - start);
    }
  }
  if (detector) {
    ademono::WriteDetectionsJsonl(staging.Path() / "detections.jsonl", all_detections);
  }
  // Move the finished results into place (replacing an older cache).
  fs::create_directories(out);
  if (depth) {
    fs::remove_all(out / "depth");
    fs::rename(staging.Path() / "depth", out / "depth");
  }
  if (detector) fs::rename(staging.Path() / "detections.jsonl", out / "detections.jsonl");
  const size_t n = end - start;
  std::cout << fmt::format("{} frames ({}..{}) -> {}\n", n, start, end - 1, out.string());
  if (depth) {
    std::cout << fmt::format("  depth: {} ({:.1f} ms/frame)\n", depth->Name(), depth_ms / n);
  }
  if (detector) {
    size_t count = 0;
    for (const auto& f : all_detections) count += f.detections.size();
    std::cout << fmt::format("  detections: {} ({} boxes, {:.1f} ms/frame)\n", detector->Name(),
                             count, detect_ms / n);
  }
  return 0;
}

const bool kRegistered = ademono::cli::RegisterCommand(
    "infer", "Run the depth model and/or detector over a dataset and cache the results",
    [](CLI::App& app) -> ademono::cli::Runner {
      auto args = std::make_shared<InferArgs>();
      app.add_option("--dataset", args->dataset,
                     "KIND:PATH (tum, kitti, euroc, 7scenes, folder, video)")
          ->required();
      app.add_option("--camera", args->camera, "camera YAML (overrides the dataset's)");
      app.add_option("--depth-model", args->depth_model, "model:FILE.onnx[,spec=SPEC.yaml]");
      app.add_option("--detector", args->detector, "model:FILE.onnx[,arch=yolox|yolov5|yolov8]");
      app.add_option("--frames", args->frames, "START:END frame range (END exclusive)");
      app.add_option("--classes", args->classes,
                     "detector classes: dynamic, all, or COCO names/ids separated by commas")
          ->capture_default_str();
      app.add_option("--score", args->score, "detector score threshold")->capture_default_str();
      app.add_option("--nms", args->nms, "detector NMS IoU threshold")->capture_default_str();
      app.add_option("--threads", args->threads, "ONNX Runtime intra-op threads")
          ->capture_default_str();
      app.add_option("--depth-format", args->depth_format,
                     "tiff: float32 metres, exact; png: uint16 millimetres")
          ->check(CLI::IsMember({"tiff", "png"}))
          ->capture_default_str();
      app.add_option("--out", args->out, "output directory")->required();
      return [args] { return RunInfer(*args); };
    });

}  // namespace
