// Real-time input (runner/realtime.h): the capture never waits for tracking, keeps at most
// `queue` frames and counts what it drops; a file is replayed no faster than recorded (times
// `speed`); a source error reaches the consumer. End to end: a synthetic office replayed faster
// than it can be tracked drops frames, and tracking survives.
#include "ademono/runner/realtime.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <opencv2/videoio.hpp>

#include "ademono/core/error.h"
#include "ademono/runner/run.h"
#include "runner_test_util.h"

namespace fs = std::filesystem;

namespace ademono {
namespace {

// Frames 0..count-1 as fast as the feed asks, timestamps 10 ms apart.
std::function<std::optional<FrameData>()> Counter(size_t count, std::atomic<size_t>* grabbed) {
  return [count, grabbed]() -> std::optional<FrameData> {
    const size_t i = (*grabbed)++;
    if (i >= count) return std::nullopt;
    FrameData f;
    f.index = i;
    f.timestamp = 0.01 * i;
    return f;
  };
}

TEST(RealtimeFeedTest, SlowConsumerGetsNewestFramesAndDropsAreCounted) {
  std::atomic<size_t> grabbed{0};
  RealtimeOptions options;
  options.pace = false;
  options.queue = 2;
  RealtimeFeed feed(Counter(300, &grabbed), options);
  size_t consumed = 0;
  long last = -1;
  while (auto frame = feed.Next()) {
    EXPECT_GT(static_cast<long>(frame->index), last);  // in order, never repeated
    last = static_cast<long>(frame->index);
    ++consumed;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // tracking is slower
  }
  const RealtimeStats stats = feed.Stats();
  EXPECT_EQ(stats.captured, 300u);
  EXPECT_EQ(consumed + stats.dropped, 300u);
  EXPECT_GT(stats.dropped, 0u);
  EXPECT_LE(stats.max_queued, 2u);  // bounded, whatever the consumer does
  EXPECT_EQ(last, 299);             // the newest frame is always delivered
}

TEST(RealtimeFeedTest, ReplaysNoFasterThanRecordedTimesSpeed) {
  std::atomic<size_t> grabbed{0};
  RealtimeOptions options;
  options.speed = 2.0;  // 30 frames 10 ms apart: 0.29 s recorded, 0.145 s at 2x
  const auto start = std::chrono::steady_clock::now();
  RealtimeFeed feed(Counter(30, &grabbed), options);
  size_t consumed = 0;
  while (feed.Next()) ++consumed;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(seconds, 0.145);
  EXPECT_EQ(consumed + feed.Stats().dropped, 30u);
}

TEST(RealtimeFeedTest, SourceErrorReachesTheConsumer) {
  RealtimeOptions options;
  options.pace = false;
  size_t i = 0;
  RealtimeFeed feed(
      [&i]() -> std::optional<FrameData> {
        if (i == 3) throw InputError("video.mp4: frame 3 does not decode");
        FrameData f;
        f.index = i++;
        return f;
      },
      options);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_THROW(
      {
        while (feed.Next()) {
        }
      },
      InputError);
}

// 60 frames replayed 1000 times faster than recorded (30,000 fps: no machine tracks that).
RunReport ReplayThousandTimesFaster(const Sequence& sequence, DepthProvider& depth) {
  RunOptions options;
  RealtimeOptions realtime;
  realtime.speed = 1000;
  options.realtime = realtime;
  return RunSequence(sequence, &depth, nullptr, options);
}

// Frames were dropped and counted, the queue stayed bounded, and tracking held on the rest.
void ExpectDropsAndTracking(const RunReport& report) {
  EXPECT_EQ(report.realtime_stats.captured, 60u);
  EXPECT_GT(report.realtime_stats.dropped, 0u);
  EXPECT_EQ(report.frames + report.realtime_stats.dropped, 60u);
  EXPECT_LE(report.realtime_stats.max_queued, 1u);
  // The frames that were tracked are the sequence's own, in order, and tracking held.
  ASSERT_GE(report.frames, 2u);
  for (size_t i = 1; i < report.per_frame.size(); ++i)
    EXPECT_GT(report.per_frame[i].frame, report.per_frame[i - 1].frame);
  EXPECT_EQ(report.per_frame.back().frame, 59u);  // the newest frame is never dropped
  EXPECT_EQ(report.lost, 0);
  EXPECT_GE(report.Tracked() + 1, report.frames);  // all but possibly the first (initialisation)
}

TEST(RealtimeRunTest, OfficeReplayedFasterThanTrackingDropsFramesAndKeepsTracking) {
  const fs::path dir = runner_test::TempDir("realtime");
  runner_test::RenderOffice(dir / "office", 60);
  const auto sequence = OpenSequence("tum:" + (dir / "office").string());
  runner_test::FrameDepth depth;
  const RunReport report = ReplayThousandTimesFaster(*sequence, depth);
  ExpectDropsAndTracking(report);
  const nlohmann::json summary = RunSummaryJson(report);
  EXPECT_EQ(summary["realtime"]["dropped"], report.realtime_stats.dropped);
  EXPECT_EQ(summary["realtime"]["captured"], 60);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// Depth for a video (which has none): the same frame index of the sequence it was made from.
class DepthOfSource : public DepthProvider {
 public:
  explicit DepthOfSource(const Sequence& source) : source_(source) {}
  std::string Name() const override { return "depth-of-source"; }
  cv::Mat Depth(const FrameData& frame, const Camera& camera) override {
    return runner_test::FrameDepth().Depth(source_.Load(frame.index), camera);
  }

 private:
  const Sequence& source_;
};

TEST(RealtimeRunTest, VideoReplayedFasterThanTrackingDropsFramesAndKeepsTracking) {
  const fs::path dir = runner_test::TempDir("realtime_video");
  const fs::path office = runner_test::RenderOffice(dir / "office", 60);
  const auto source = OpenSequence("tum:" + office.string());
  const fs::path video = dir / "office.avi";
  {
    const FrameData first = source->Load(0);
    cv::VideoWriter writer(video.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30.0,
                           first.image.size());
    ASSERT_TRUE(writer.isOpened());
    for (size_t i = 0; i < source->Size(); ++i) writer.write(source->Load(i).image);
  }
  // `video:FILE --realtime`: the file at its recorded rate, here 1000 times faster.
  const auto sequence = OpenSequence("video:" + video.string(), office / "camera.yaml");
  ASSERT_EQ(sequence->Size(), 60u);
  DepthOfSource depth(*source);
  ExpectDropsAndTracking(ReplayThousandTimesFaster(*sequence, depth));
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace ademono
