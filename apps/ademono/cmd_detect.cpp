// `ademono detect`: run an object detector on images, print the detections and optionally write
// them as JSON (the layout of ../shared/images/expected_detections.json).
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/detect/detector_factory.h"
#include "command.h"

namespace {

double Round(double value, double step) { return std::round(value / step) * step; }

struct DetectArgs {
  std::string detector;
  std::string json_out;
  std::string classes = "all";
  float score = 0.3f;
  float nms = 0.45f;
  bool class_agnostic = false;
  int threads = 1;
  std::vector<std::string> images;
};

int RunDetect(const DetectArgs& args) {
  ademono::DetectorOptions options;
  options.score_threshold = args.score;
  options.nms_iou = args.nms;
  options.class_ids = ademono::ParseClassList(args.classes);
  options.class_agnostic_nms = args.class_agnostic;
  options.num_threads = args.threads;
  // Read every image first so a bad one fails before any work or output.
  std::vector<cv::Mat> images;
  std::map<std::string, size_t> keys;
  for (const auto& path : args.images) {
    images.push_back(ademono::ReadImage(path, cv::IMREAD_COLOR));
    const std::string key = std::filesystem::path(path).filename().string();
    if (!keys.emplace(key, keys.size()).second) {
      ademono::ThrowInputError(path, "two input images share the file name '" + key + "'");
    }
  }
  auto detector = ademono::MakeDetector(args.detector, options);
  nlohmann::ordered_json json;
  json["model"] = detector->Name();
  json["score_threshold"] = Round(args.score, 1e-6);
  json["nms_iou"] = Round(args.nms, 1e-6);
  json["class_agnostic_nms"] = args.class_agnostic;
  json["images"] = nlohmann::ordered_json::object();
  double total_ms = 0.0;
  for (size_t i = 0; i < images.size(); ++i) {
    const std::filesystem::path path = args.images[i];
    ademono::FrameData frame;
    frame.index = i;
    frame.name = path.stem().string();
    frame.image = images[i];
    const auto start = std::chrono::steady_clock::now();
    const auto detections = detector->Detect(frame);
    total_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::cout << fmt::format("{}: {} detection{}\n", path.filename().string(), detections.size(),
                             detections.size() == 1 ? "" : "s");
    auto& entry = json["images"][path.filename().string()];
    entry["width"] = images[i].cols;
    entry["height"] = images[i].rows;
    entry["detections"] = nlohmann::ordered_json::array();
    for (const auto& d : detections) {
      std::cout << fmt::format("  {:<14} {:.3f}  x {:.1f} y {:.1f} w {:.1f} h {:.1f}\n",
                               d.class_name, d.score, d.box.x, d.box.y, d.box.width, d.box.height);
      nlohmann::ordered_json item;
      item["class_id"] = d.class_id;
      item["class"] = d.class_name;
      item["score"] = Round(d.score, 1e-4);
      item["box_xywh"] = {Round(d.box.x, 0.01), Round(d.box.y, 0.01), Round(d.box.width, 0.01),
                          Round(d.box.height, 0.01)};
      entry["detections"].push_back(item);
    }
  }
  std::cerr << fmt::format(
      "{} image{}, {:.1f} ms per image (pre-processing, inference, decoding)\n", images.size(),
      images.size() == 1 ? "" : "s", total_ms / std::max<size_t>(1, images.size()));
  if (!args.json_out.empty()) ademono::WriteTextFileAtomic(args.json_out, json.dump(1) + "\n");
  return 0;
}

const bool kRegistered = ademono::cli::RegisterCommand(
    "detect", "Detect objects in images with an ONNX YOLO model",
    [](CLI::App& app) -> ademono::cli::Runner {
      auto args = std::make_shared<DetectArgs>();
      app.add_option("--detector", args->detector,
                     "model:FILE.onnx[,arch=yolox|yolov5|yolov8] (also none, cache:FILE.jsonl)")
          ->required();
      app.add_option("--json", args->json_out, "write the detections as JSON");
      app.add_option("--classes", args->classes,
                     "all, dynamic, or COCO class names/ids separated by commas")
          ->capture_default_str();
      app.add_option("--score", args->score, "score threshold")->capture_default_str();
      app.add_option("--nms", args->nms, "NMS IoU threshold")->capture_default_str();
      app.add_flag("--class-agnostic-nms", args->class_agnostic,
                   "one NMS over all classes instead of per class");
      app.add_option("--threads", args->threads, "ONNX Runtime intra-op threads")
          ->capture_default_str();
      app.add_option("images", args->images, "image files")->required();
      return [args] { return RunDetect(*args); };
    });

}  // namespace
