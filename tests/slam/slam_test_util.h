#pragma once
// Helpers for SLAM tests on a short 7-Scenes slice: a Sequence wrapper that remaps frames and
// injects faults (no depth, black image), and pose error against the ground truth.

#include <memory>
#include <string>
#include <vector>

#include "ademono/depth/sensor_depth.h"
#include "ademono/io/sequence.h"
#include "ademono/io/trajectory.h"

namespace ademono::testing_util {

inline std::string SevenScenesSpec() {
  return std::string("7scenes:") + ADEMONO_SHARED_DIR + "/data/7scenes-seq-a";
}

// The frame's depth as `--depth sensor` gives it (non-finite readings as 0); a frame without depth
// (Fault::kNoDepth) stays without, so System's own handling of it is what the tests see.
inline cv::Mat SensorDepth(const FrameData& frame) {
  if (frame.depth.empty()) return {};
  return SensorDepthProvider(nullptr).Depth(frame, Camera{});
}

enum class Fault { kNone, kNoDepth, kBlack };

class FaultySequence : public Sequence {
 public:
  struct Entry {
    size_t source;
    Fault fault = Fault::kNone;
  };
  FaultySequence(std::unique_ptr<Sequence> base, std::vector<Entry> entries)
      : base_(std::move(base)), entries_(std::move(entries)) {}
  std::string Kind() const override { return base_->Kind(); }
  std::filesystem::path Path() const override { return base_->Path(); }
  size_t Size() const override { return entries_.size(); }
  const Camera& GetCamera() const override { return base_->GetCamera(); }
  bool HasDepth() const override { return base_->HasDepth(); }
  bool HasGroundTruth() const override { return base_->HasGroundTruth(); }
  double Timestamp(size_t i) const override { return i / 30.0; }
  FrameData Load(size_t i) const override {
    FrameData frame = base_->Load(entries_[i].source);
    frame.index = i;
    frame.timestamp = Timestamp(i);
    if (entries_[i].fault == Fault::kNoDepth) frame.depth.setTo(0.f);
    if (entries_[i].fault == Fault::kBlack) frame.image.setTo(cv::Scalar::all(0));
    return frame;
  }

 private:
  std::unique_ptr<Sequence> base_;
  std::vector<Entry> entries_;
};

inline std::unique_ptr<Sequence> Slice(size_t begin, size_t end,
                                       const std::vector<std::pair<size_t, Fault>>& faults = {},
                                       const std::vector<size_t>& duplicate_after = {}) {
  std::vector<FaultySequence::Entry> entries;
  for (size_t s = begin; s < end; ++s) {
    Fault fault = Fault::kNone;
    for (const auto& [at, f] : faults) {
      if (at == s) fault = f;
    }
    entries.push_back({s, fault});
    for (size_t d : duplicate_after) {
      if (d == s) entries.push_back({s, Fault::kNone});
    }
  }
  return std::make_unique<FaultySequence>(OpenSequence(SevenScenesSpec()), std::move(entries));
}

}  // namespace ademono::testing_util
