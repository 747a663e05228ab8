#pragma once
// Helpers for runner tests: a short synthetic office sequence (rendered once per test binary,
// so no ../shared), its sensor depth and its ground-truth boxes as providers.

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "ademono/depth/sensor_depth.h"
#include "ademono/perception/depth_provider.h"
#include "ademono/perception/detection.h"
#include "ademono/perception/detection_io.h"
#include "ademono/synth/generator.h"

namespace ademono::runner_test {

// The sequence's own depth, non-finite readings as 0: `--depth sensor`'s provider under its own
// name, so tests can tell it was the one used.
class FrameDepth : public SensorDepthProvider {
 public:
  FrameDepth() : SensorDepthProvider(nullptr) {}
  std::string Name() const override { return "frame-depth"; }
};

// The synthetic sequence's detections.jsonl, matched by frame index.
class TruthBoxes : public Detector {
 public:
  explicit TruthBoxes(const std::filesystem::path& jsonl) {
    for (FrameDetections& f : ReadDetectionsJsonl(jsonl)) by_index_[f.frame] = f.detections;
  }
  std::string Name() const override { return "truth-boxes"; }
  std::vector<Detection> Detect(const FrameData& frame) override {
    const auto it = by_index_.find(frame.index);
    return it == by_index_.end() ? std::vector<Detection>{} : it->second;
  }

 private:
  std::map<size_t, std::vector<Detection>> by_index_;
};

inline std::filesystem::path TempDir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("ademono_runner_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

// An office with two walking persons (and the static mannequin), `frames` frames, seed 3.
inline std::filesystem::path RenderOffice(const std::filesystem::path& dir, size_t frames) {
  synth::GeneratorOptions options;
  options.scene.scene = "office";
  options.scene.frames = frames;
  options.scene.seed = 3;
  options.scene.persons = 2;
  synth::GenerateSequence(options, dir);
  return dir;
}

}  // namespace ademono::runner_test
