#include "ademono/runner/pipeline.h"

#include <algorithm>
#include <deque>
#include <future>
#include <optional>
#include <utility>

#include "ademono/core/memory.h"
#include "ademono/core/timing.h"
#include "ademono/core/worker_pool.h"

namespace ademono {
namespace {

struct Prepared {
  FrameData frame;
  cv::Mat depth;
  std::vector<Detection> detections;
  ExtractedFrame extracted;
  double decode_ms = 0, depth_ms = 0, detection_ms = 0;
  double cpu_ms = 0;  // CPU of the thread(s) that prepared it, decode included
  double decode_cpu_ms = 0;
};

// Depth, detections, ORB features and keypoint depths of a loaded frame. With `helpers`, the ORB
// extraction (which needs only the image) runs on a helper thread beside the depth network, and
// so does the detector when there is a depth network too (the method's three parallel branches:
// two single-threaded ONNX sessions on two cores); either way the result is the same.
void PrepareLoaded(Prepared& p, const Sequence& sequence, DepthProvider* depth, Detector* detector,
                   const System& system, WorkerPool* helpers) {
  const double cpu_start = ThreadCpuMs();
  std::future<std::pair<ExtractedFrame, double>> features;
  std::future<double> detected;  // CPU ms; fills p.detections and p.detection_ms
  auto detect = [detector, &p] {
    const double cpu = ThreadCpuMs();
    const auto start = Now();
    p.detections = detector->Detect(p.frame);
    p.detection_ms = MsSince(start);
    return ThreadCpuMs() - cpu;
  };
  if (helpers != nullptr) {
    features = helpers->Submit([&system, &p] {
      const double cpu = ThreadCpuMs();
      ExtractedFrame e = system.ExtractFeatures(p.frame);
      return std::make_pair(std::move(e), ThreadCpuMs() - cpu);
    });
    if (detector != nullptr && depth != nullptr && depth->Name() != "sensor")
      detected = helpers->Submit(detect);
  }
  double detection_cpu = 0;
  try {
    const auto start = Now();
    if (depth != nullptr) p.depth = depth->Depth(p.frame, sequence.GetCamera());
    p.depth_ms = MsSince(start);
    if (detected.valid()) {
      detection_cpu = detected.get();
    } else if (detector != nullptr) {
      detect();
    }
  } catch (...) {
    // Both read p.frame and write p: neither may outlive this call.
    if (detected.valid()) detected.wait();
    if (features.valid()) features.wait();
    throw;
  }
  double extraction_cpu = 0;
  if (features.valid()) {
    std::tie(p.extracted, extraction_cpu) = features.get();
  } else {
    p.extracted = system.ExtractFeatures(p.frame);
  }
  system.AddDepths(p.extracted, p.depth);
  p.cpu_ms += ThreadCpuMs() - cpu_start + extraction_cpu + detection_cpu;
}

Prepared Prepare(const Sequence& sequence, DepthProvider* depth, Detector* detector,
                 const System& system, WorkerPool* helpers, size_t i) {
  Prepared p;
  const double cpu_start = ThreadCpuMs();
  const auto start = Now();
  // Depth images are decoded only for a provider that reads them (sensor, simulated).
  p.frame = ReadsSequenceDepth(depth) ? sequence.Load(i) : sequence.LoadWithoutDepth(i);
  p.decode_ms = MsSince(start);
  p.cpu_ms = p.decode_cpu_ms = ThreadCpuMs() - cpu_start;
  PrepareLoaded(p, sequence, depth, detector, system, helpers);
  return p;
}

}  // namespace

PipelineResult RunPipeline(const Sequence& sequence, DepthProvider* depth, Detector* detector,
                           System& system, const PipelineOptions& options) {
  PipelineResult result;
  const size_t end = std::min(options.end, sequence.Size());
  const auto wall_start = Now();
  // Preparations in flight, in frame order: the front is the next frame to track.
  std::deque<std::future<Prepared>> ahead;
  const size_t depth_ahead = static_cast<size_t>(std::max(1, options.prefetch_frames));
  // Extraction beside depth and detection only when they are real work (a network or a
  // detector); a sensor depth map costs nothing to hide behind.
  const bool parallel_extraction =
      options.overlap && (detector != nullptr || (depth != nullptr && depth->Name() != "sensor"));
  result.prefetched = options.overlap && options.feed == nullptr;
  // Threads that live for the run (worker_pool.h says why). Each preparation in flight may hand
  // its extraction and its detector to two helpers. The helpers are declared first so that they
  // outlive the preparations waiting for them.
  std::optional<WorkerPool> helpers, preparers;
  if (result.prefetched) {
    if (parallel_extraction) helpers.emplace(2 * static_cast<int>(depth_ahead), "ademono-help");
    preparers.emplace(static_cast<int>(depth_ahead), "ademono-prep");
  }
  WorkerPool* helper_pool = helpers ? &*helpers : nullptr;
  auto stop_requested = [&] {
    if (options.stop == nullptr || !options.stop->load()) return false;
    result.stopped = true;
    return true;  // a preparation in flight is finished by the pool's destructor
  };
  // `cpu_ms`: what the tracking thread already spent on this frame (decode/extraction inline).
  auto track = [&](Prepared& current, double cpu_ms, double wait_ms, bool prefetched) {
    const double cpu_start = ThreadCpuMs();
    TrackResult r;
    try {
      r = system.TrackFrame(current.frame, current.depth, current.detections,
                            std::move(current.extracted));
    } catch (...) {
      for (auto& f : ahead) f.wait();  // never leave a worker running on a dying pipeline
      throw;
    }
    FrameTiming t;
    t.decode_ms = current.decode_ms;
    t.extraction_ms = r.extraction_ms;
    t.keypoint_depth_ms = r.keypoint_depth_ms;
    t.depth_ms = current.depth_ms;
    t.detection_ms = current.detection_ms;
    t.filter_ms = r.filter_ms;
    t.tracking_ms = r.tracking_ms;
    t.mapping_ms = r.mapping_ms;
    t.prefetch_wait_ms = wait_ms;
    t.tracking_thread_ms = cpu_ms + ThreadCpuMs() - cpu_start;
    t.prefetch_thread_ms = prefetched ? current.cpu_ms : 0;
    result.timings.push_back(t);
    if (options.on_frame) options.on_frame(current.frame, current.depth, current.detections, r);
    FrameData gt;
    gt.index = current.frame.index;
    gt.timestamp = current.frame.timestamp;
    gt.name = current.frame.name;
    gt.world_from_cam_gt = current.frame.world_from_cam_gt;
    result.ground_truth_frames.push_back(std::move(gt));
    ++result.frames;
    if (result.frames % kReleaseFreedMemoryEveryFrames == 0) ReleaseFreedMemory();
  };
  if (options.feed != nullptr) {
    while (!stop_requested()) {
      std::optional<FrameData> frame = options.feed->Next();
      if (!frame) break;
      Prepared current;
      current.frame = std::move(*frame);
      PrepareLoaded(current, sequence, depth, detector, system, nullptr);
      track(current, current.cpu_ms, 0, false);
    }
  } else {
    size_t launched = options.start + 1;  // the next frame to hand to a worker
    for (size_t i = options.start; i < end && !stop_requested(); ++i) {
      Prepared current;
      double inline_cpu = 0, wait_ms = 0;
      const bool prefetched = options.overlap && !ahead.empty();
      if (prefetched) {
        const auto wait_start = Now();
        std::future<Prepared> front = std::move(ahead.front());
        ahead.pop_front();
        try {
          current = front.get();  // rethrows a provider's InputError here, in frame order
        } catch (...) {
          for (auto& f : ahead) f.wait();
          throw;
        }
        wait_ms = MsSince(wait_start);
      } else {
        current = Prepare(sequence, depth, detector, system, nullptr, i);
        inline_cpu =
            current.cpu_ms - current.decode_cpu_ms;  // the tracking thread: decode excluded
      }
      while (options.overlap && launched < end && launched <= i + depth_ahead) {
        ahead.push_back(preparers->Submit([&sequence, depth, detector, &system, helper_pool,
                                           frame = launched] {
          return Prepare(sequence, depth, detector, system, helper_pool, frame);
        }));
        ++launched;
      }
      track(current, inline_cpu, wait_ms, prefetched);
    }
    for (auto& f : ahead) f.wait();  // stopped early: let the workers finish
  }
  result.wall_seconds = MsSince(wall_start) / 1000.0;
  return result;
}

}  // namespace ademono
