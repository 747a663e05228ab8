#include "ademono/runner/realtime.h"

#include <algorithm>
#include <chrono>
#include <memory>

#include "ademono/core/thread_name.h"

namespace ademono {

RealtimeFeed::RealtimeFeed(std::function<std::optional<FrameData>()> grab,
                           const RealtimeOptions& options)
    : grab_(std::move(grab)), options_(options) {
  options_.queue = std::max<size_t>(1, options_.queue);
  thread_ = std::thread([this] {
    SetCurrentThreadName("ademono-capture");
    Capture();
  });
}

RealtimeFeed::~RealtimeFeed() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  ready_.notify_all();
  thread_.join();
}

void RealtimeFeed::Capture() {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  std::optional<double> first_timestamp;
  try {
    for (;;) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (stopping_) break;
      }
      std::optional<FrameData> frame = grab_();
      if (!frame) break;
      if (options_.pace) {
        if (!first_timestamp) first_timestamp = frame->timestamp;
        const double due = (frame->timestamp - *first_timestamp) / options_.speed;
        std::unique_lock<std::mutex> lock(mutex_);
        // Wakes early only to stop.
        ready_.wait_until(
            lock,
            start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(due)),
            [this] { return stopping_; });
        if (stopping_) break;
      }
      std::lock_guard<std::mutex> lock(mutex_);
      ++stats_.captured;
      if (queue_.size() >= options_.queue) {
        queue_.pop_front();  // the oldest waiting frame is the one nobody needs any more
        ++stats_.dropped;
      }
      queue_.push_back(std::move(*frame));
      stats_.max_queued = std::max(stats_.max_queued, queue_.size());
      ready_.notify_all();
    }
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex_);
    error_ = std::current_exception();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  ended_ = true;
  ready_.notify_all();
}

std::optional<FrameData> RealtimeFeed::Next() {
  std::unique_lock<std::mutex> lock(mutex_);
  ready_.wait(lock, [this] { return !queue_.empty() || ended_; });
  if (queue_.empty()) {
    if (error_) std::rethrow_exception(error_);
    return std::nullopt;
  }
  FrameData frame = std::move(queue_.front());
  queue_.pop_front();
  return frame;
}

RealtimeStats RealtimeFeed::Stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

std::unique_ptr<RealtimeFeed> MakeRealtimeFeed(const Sequence& sequence, size_t start, size_t end,
                                               RealtimeOptions options, bool with_depth) {
  if (sequence.Kind() == "camera") options.pace = false;
  end = std::min(end, sequence.Size());
  auto next = std::make_shared<size_t>(start);
  return std::make_unique<RealtimeFeed>(
      [&sequence, next, end, with_depth]() -> std::optional<FrameData> {
        if (*next >= end) return std::nullopt;
        const size_t i = (*next)++;
        return with_depth ? sequence.Load(i) : sequence.LoadWithoutDepth(i);
      },
      options);
}

}  // namespace ademono
