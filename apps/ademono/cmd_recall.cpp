// `ademono recall`: a detector's recall on a synthetic sequence (`ademono synth`), per class,
// against the sequence's ground-truth boxes (detections.jsonl, IoU >= --min-iou). The work is in
// synth/detector_recall.h.
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <spdlog/spdlog.h>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/detect/detector_factory.h"
#include "ademono/io/sequence.h"
#include "ademono/synth/detector_recall.h"
#include "command.h"
#include "run_options.h"

namespace fs = std::filesystem;

namespace ademono::cli {
namespace {

struct RecallArgs {
  std::string sequence;
  std::string detector;
  std::string frames;
  double min_iou = 0.5;
  float score = 0.3f;
  std::string json_out;
  std::string save_detections;
};

int Recall(const RecallArgs& args) {
  if (!(args.min_iou > 0.0 && args.min_iou <= 1.0))
    throw InputError("--min-iou must be in (0, 1]");
  const fs::path truth_path = fs::path(args.sequence) / "detections.jsonl";
  RequireFile(truth_path);
  const std::vector<FrameDetections> truth_all = ReadDetectionsJsonl(truth_path);
  const std::unique_ptr<Sequence> sequence = OpenSequence("tum:" + args.sequence);
  size_t start = 0, end = sequence->Size();
  if (!args.frames.empty()) ParseFrames(args.frames, sequence->Size(), &start, &end);
  DetectorOptions options;
  options.score_threshold = args.score;
  std::unique_ptr<Detector> detector = MakeDetector(args.detector, options);
  std::vector<FrameDetections> truth, detected;
  for (size_t i = start; i < end && i < sequence->Size(); ++i) {
    const FrameData frame = sequence->Load(i);
    FrameDetections d;
    d.frame = i;
    d.timestamp = frame.timestamp;
    d.name = frame.name;
    d.detections = detector->Detect(frame);
    detected.push_back(std::move(d));
  }
  // The truth of the scored frames only, matched by name (synth names frames by timestamp).
  for (const FrameDetections& t : truth_all) {
    for (const FrameDetections& d : detected)
      if (d.name == t.name) truth.push_back(t);
  }
  if (truth.size() != detected.size())
    ThrowInputError(truth_path, "has no entry for some frames of the sequence");
  // With objects.jsonl (synth --actor-photos), each true box is labelled with its object:
  // the box with the same extent among that frame's objects.
  std::vector<std::vector<std::string>> labels;
  const fs::path objects_path = fs::path(args.sequence) / "objects.jsonl";
  const fs::path scene_path = fs::path(args.sequence) / "scene.json";
  const bool labelled = fs::is_regular_file(objects_path) && fs::is_regular_file(scene_path);
  if (labelled) {
    std::map<int, std::string> names;
    try {
      const nlohmann::json scene = nlohmann::json::parse(ReadTextFile(scene_path));
      for (const auto& o : scene.at("objects")) {
        std::string label = o.at("name").get<std::string>() +
                            (o.at("moving").get<bool>() ? " (moving" : " (static");
        if (o.contains("appearance")) label += ", " + o.at("appearance").get<std::string>();
        names[o.at("id").get<int>()] = label + ")";
      }
    } catch (const nlohmann::json::exception& e) {
      ThrowInputError(scene_path, std::string("bad scene description: ") + e.what());
    }
    std::map<std::string, nlohmann::json> objects_by_frame;
    std::istringstream lines(ReadTextFile(objects_path));
    std::string line;
    while (std::getline(lines, line)) {
      if (line.empty()) continue;
      try {
        nlohmann::json j = nlohmann::json::parse(line);
        objects_by_frame[j.at("name").get<std::string>()] = j.at("objects");
      } catch (const nlohmann::json::exception& e) {
        ThrowInputError(objects_path, std::string("bad line: ") + e.what());
      }
    }
    for (const FrameDetections& t : truth) {
      std::vector<std::string> frame_labels;
      const auto it = objects_by_frame.find(t.name);
      for (const Detection& d : t.detections) {
        std::string label = "?";
        if (it != objects_by_frame.end()) {
          for (const auto& o : it->second) {
            const auto& b = o.at("box_xywh");
            if (b[0].get<float>() == d.box.x && b[1].get<float>() == d.box.y &&
                b[2].get<float>() == d.box.width && b[3].get<float>() == d.box.height) {
              label = names[o.at("id").get<int>()];
              break;
            }
          }
        }
        frame_labels.push_back(label);
      }
      labels.push_back(std::move(frame_labels));
    }
  }
  const synth::RecallResult result =
      synth::DetectorRecall(truth, detected, args.min_iou, labelled ? &labels : nullptr);
  std::cout << result.Markdown();
  if (!args.json_out.empty()) WriteTextFileAtomic(args.json_out, result.ToJson().dump(1) + "\n");
  if (!args.save_detections.empty()) WriteDetectionsJsonl(args.save_detections, detected);
  return 0;
}

const bool kRegistered = RegisterCommand(
    "recall",
    "A detector's per-class recall on a synthetic sequence against its ground-truth boxes",
    [](CLI::App& app) -> Runner {
      auto args = std::make_shared<RecallArgs>();
      app.add_option("--sequence", args->sequence, "folder written by `ademono synth`")
          ->required();
      app.add_option("--detector", args->detector, "detector spec, e.g. model:yolox_nano.onnx")
          ->required();
      app.add_option("--frames", args->frames, "START:END subset (END exclusive)");
      app.add_option("--min-iou", args->min_iou, "IoU for a true box to count as found")
          ->capture_default_str();
      app.add_option("--score", args->score, "detector score threshold")->capture_default_str();
      app.add_option("--json", args->json_out, "write the per-class recall as JSON");
      app.add_option("--save-detections", args->save_detections,
                     "write the detections as a detections cache (JSON lines)");
      return [args] { return Recall(*args); };
    });

}  // namespace
}  // namespace ademono::cli
