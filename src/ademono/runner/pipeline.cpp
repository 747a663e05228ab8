#include "ademono/runner/pipeline.h"

#include <algorithm>
#include <future>
#include <optional>
#include <utility>

#include "ademono/core/timing.h"

namespace ademono {
namespace {

struct Prepared {
  FrameData frame;
  cv::Mat depth;
  std::vector<Detection> detections;
  double depth_ms = 0, detection_ms = 0;
};

Prepared PrepareFrame(FrameData frame, const Sequence& sequence, DepthProvider* depth,
                      Detector* detector) {
  Prepared p;
  p.frame = std::move(frame);
  auto start = Now();
  if (depth != nullptr) p.depth = depth->Depth(p.frame, sequence.GetCamera());
  p.depth_ms = MsSince(start);
  start = Now();
  if (detector != nullptr) p.detections = detector->Detect(p.frame);
  p.detection_ms = MsSince(start);
  return p;
}

Prepared Prepare(const Sequence& sequence, DepthProvider* depth, Detector* detector, size_t i) {
  return PrepareFrame(sequence.Load(i), sequence, depth, detector);
}

}  // namespace

PipelineResult RunPipeline(const Sequence& sequence, DepthProvider* depth, Detector* detector,
                           System& system, const PipelineOptions& options) {
  PipelineResult result;
  const size_t end = std::min(options.end, sequence.Size());
  const auto wall_start = Now();
  std::future<Prepared> next;
  auto stop_requested = [&] {
    if (options.stop == nullptr || !options.stop->load()) return false;
    result.stopped = true;
    return true;  // a prefetch in flight is waited for by the future's destructor
  };
  auto track = [&](const Prepared& current) {
    TrackResult r;
    try {
      r = system.TrackFrame(current.frame, current.depth, current.detections);
    } catch (...) {
      if (next.valid()) next.wait();  // never leave the worker running on a dying pipeline
      throw;
    }
    FrameTiming t;
    t.extraction_ms = r.extraction_ms;
    t.depth_ms = current.depth_ms;
    t.detection_ms = current.detection_ms;
    t.filter_ms = r.filter_ms;
    t.tracking_ms = r.tracking_ms;
    t.mapping_ms = r.mapping_ms;
    result.timings.push_back(t);
    if (options.on_frame) options.on_frame(current.frame, current.depth, current.detections, r);
    FrameData gt;
    gt.index = current.frame.index;
    gt.timestamp = current.frame.timestamp;
    gt.name = current.frame.name;
    gt.world_from_cam_gt = current.frame.world_from_cam_gt;
    result.ground_truth_frames.push_back(std::move(gt));
    ++result.frames;
  };
  if (options.feed != nullptr) {
    while (!stop_requested()) {
      std::optional<FrameData> frame = options.feed->Next();
      if (!frame) break;
      track(PrepareFrame(std::move(*frame), sequence, depth, detector));
    }
  } else {
    for (size_t i = options.start; i < end && !stop_requested(); ++i) {
      Prepared current;
      if (options.overlap && next.valid()) {
        current = next.get();  // rethrows a provider's InputError here, in frame order
      } else {
        current = Prepare(sequence, depth, detector, i);
      }
      if (options.overlap && i + 1 < end) {
        next = std::async(std::launch::async, Prepare, std::cref(sequence), depth, detector, i + 1);
      }
      track(current);
    }
  }
  result.wall_seconds = MsSince(wall_start) / 1000.0;
  return result;
}

}  // namespace ademono
