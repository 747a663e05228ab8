#pragma once
// The per-frame loop of a run (runner/run.h): load (decode) a frame, compute its depth and
// detections, extract its ORB features and keypoint depths, track it. With `overlap`, all of that
// but tracking is done for frame k+1 on a prefetch thread while frame k is tracked (a one-frame
// prefetch; inside it, ORB extraction runs beside the depth network and the detector when there
// are any); the tracking thread does filters + tracking + mapping's merges only. Results are
// identical to the sequential loop because providers and extraction are pure functions of the
// frame and tracking still sees frames in order.

#include <atomic>
#include <cstddef>
#include <functional>
#include <vector>

#include "ademono/io/sequence.h"
#include "ademono/perception/depth_provider.h"
#include "ademono/perception/detection.h"
#include "ademono/runner/realtime.h"
#include "ademono/slam/system.h"

namespace ademono {

struct PipelineOptions {
  size_t start = 0;       // first frame (inclusive)
  size_t end = SIZE_MAX;  // last frame (exclusive), clamped to the sequence size
  bool overlap = true;    // prefetch depth/detections of the next frame
  // With overlap: how many frames ahead are prepared at once (1: frame k+1 while k is tracked).
  // At 1 the preparation (decode and ORB, or a depth network) bounds the rate and leaves a core
  // idle; at 2 the preparations of k+1 and k+2 overlap on both cores (seq-a with sensor depth
  // 47.5 -> 75.4 frames/s, tools/bench_throughput.sh). Same outputs for any value (each frame's
  // preparation is a pure function of the frame; tracking still takes them in order).
  int prefetch_frames = 2;
  // Set from elsewhere (a SIGINT handler): the loop stops before the next frame; the frames done
  // so far stay valid (PipelineResult::stopped).
  const std::atomic<bool>* stop = nullptr;
  // Real-time input: frames come from this feed (the newest captured, runner/realtime.h) until
  // it ends, instead of Load(start..end); no prefetch (the next frame is whatever is newest when
  // tracking is ready for it).
  RealtimeFeed* feed = nullptr;
  // Called after each frame (in order, on the calling thread).
  std::function<void(const FrameData&, const cv::Mat& depth, const std::vector<Detection>&,
                     const TrackResult&)>
      on_frame;
};

// Wall milliseconds per stage of one frame, except tracking_thread_ms and prefetch_thread_ms:
// CPU milliseconds of the tracking (calling) thread for this frame (everything the loop does for
// it there except the on_frame callback and the image decode: filters, tracking, mapping's work
// on that thread, and extraction, depth and detection too without overlap) and of the prefetch
// work for it, decode included (0 without overlap).
struct FrameTiming {
  double decode_ms = 0, extraction_ms = 0, keypoint_depth_ms = 0, depth_ms = 0, detection_ms = 0,
         filter_ms = 0, tracking_ms = 0, mapping_ms = 0;
  double prefetch_wait_ms = 0;  // the tracking thread waited this long for the prefetch (wall)
  double tracking_thread_ms = 0, prefetch_thread_ms = 0;
};

struct PipelineResult {
  std::vector<FrameTiming> timings;            // one per processed frame
  std::vector<FrameData> ground_truth_frames;  // index, timestamp and gt pose (images dropped)
  size_t frames = 0;
  double wall_seconds = 0;
  bool stopped = false;  // options.stop ended the loop before the last frame
  bool prefetched = false;  // decode, depth, detection and extraction ran on the prefetch threads
};

// Throws InputError from the sequence or the providers (e.g. a missing cached depth map).
// `depth` may be null (no depth: 2-dof tracking only, needs an initialised map from elsewhere,
// so in practice always given); `detector` may be null (no detections).
PipelineResult RunPipeline(const Sequence& sequence, DepthProvider* depth, Detector* detector,
                           System& system, const PipelineOptions& options);

}  // namespace ademono
