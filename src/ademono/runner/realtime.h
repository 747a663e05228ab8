#pragma once
// Real-time input (`ademono run --realtime`, always for `camera:`): a capture thread takes frames
// from the source at the source's own rate and keeps only the newest `queue` of them; when
// tracking falls behind, older frames are dropped and counted instead of queueing without bound.
// A file source (video, or any dataset) is replayed at its recorded rate (timestamps), `speed`
// times faster, through the same code a camera uses. Not deterministic: which frames are dropped
// depends on the machine's speed.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "ademono/io/sequence.h"

namespace ademono {

struct RealtimeOptions {
  size_t queue = 1;    // frames kept waiting for tracking (the newest ones)
  double speed = 1.0;  // replay rate of a file source, times its recorded rate
  // Sleep until each frame's timestamp (files). A camera paces itself: its read blocks.
  bool pace = true;
};

struct RealtimeStats {
  size_t captured = 0;  // frames taken from the source
  size_t dropped = 0;   // captured but never tracked: a newer frame replaced them in the queue
  size_t max_queued = 0;
};

class RealtimeFeed {
 public:
  // `grab` returns the source's next frame, nullopt at its end; it runs on the capture thread
  // only. An exception from it (InputError) is rethrown by Next() after the queued frames.
  RealtimeFeed(std::function<std::optional<FrameData>()> grab, const RealtimeOptions& options);
  ~RealtimeFeed();  // stops capturing and joins
  RealtimeFeed(const RealtimeFeed&) = delete;
  RealtimeFeed& operator=(const RealtimeFeed&) = delete;

  // The oldest queued frame; blocks until there is one. nullopt once the source has ended and
  // the queue is empty.
  std::optional<FrameData> Next();
  RealtimeStats Stats() const;

 private:
  void Capture();

  std::function<std::optional<FrameData>()> grab_;
  RealtimeOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<FrameData> queue_;
  RealtimeStats stats_;
  bool ended_ = false, stopping_ = false;
  std::exception_ptr error_;
  std::thread thread_;
};

// A feed over frames [start, end) of `sequence`, paced by their timestamps unless the sequence
// is a live camera (Kind() "camera"), which paces itself. Frames carry their depth images only
// `with_depth` (a depth provider that reads them: DepthProvider::ReadsSequenceDepth).
std::unique_ptr<RealtimeFeed> MakeRealtimeFeed(const Sequence& sequence, size_t start, size_t end,
                                               RealtimeOptions options, bool with_depth = true);

}  // namespace ademono
