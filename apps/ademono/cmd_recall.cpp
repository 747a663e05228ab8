// `ademono recall`: a detector's recall on a synthetic sequence (`ademono synth`), per class,
// against the sequence's ground-truth boxes (detections.jsonl, IoU >= --min-iou). The work is in
// synth/detector_recall.h.
#include <iostream>
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
  const synth::RecallResult result = synth::DetectorRecall(truth, detected, args.min_iou);
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
