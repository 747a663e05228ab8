// A video file read with cv::VideoCapture. The frame count and timestamps (index / fps) are
// established once at open by grabbing through the file, because container frame counts are
// often wrong. Decoding is sequential: the capture is kept at the next frame so in-order Load()
// costs one decode, and the last few decoded frames are kept, so that the pipeline's workers,
// which may ask for k+2 just before k+1, never send it back; going further back reopens the
// file. A mutex serialises access to the capture.
// Also the live camera (camera:N), read through the same OpenCV capture.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <deque>
#include <mutex>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/io/file_sequence.h"

namespace fs = std::filesystem;

namespace ademono {

namespace {

class VideoSequence : public Sequence {
 public:
  VideoSequence(fs::path file, Camera camera) : file_(std::move(file)), camera_(camera) {
    Reopen();
    double fps = capture_.get(cv::CAP_PROP_FPS);
    if (!(fps > 0 && fps < 1000)) fps = 30.0;
    const double declared = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    size_t count = 0;
    while (capture_.grab()) ++count;
    if (count == 0) ThrowInputError(file_, "sequence has no frames");
    // A declared count (exact in AVI/MP4 headers, at most one off when estimated) far above the
    // frames that decode means a cut-off file or a corrupt frame: the run would silently stop
    // there, so say so instead.
    if (declared > 0 && static_cast<double>(count) + 1 < declared) {
      ThrowInputError(file_, "frame " + std::to_string(count) + " does not decode, but the video "
                             "declares " + std::to_string(std::llround(declared)) +
                             " frames (cut off or corrupt)");
    }
    for (size_t i = 0; i < count; ++i) timestamps_.push_back(static_cast<double>(i) / fps);
    Reopen();
  }

  std::string Kind() const override { return "video"; }
  fs::path Path() const override { return file_; }
  size_t Size() const override { return timestamps_.size(); }
  const Camera& GetCamera() const override { return camera_; }
  bool HasDepth() const override { return false; }
  bool HasGroundTruth() const override { return false; }
  double Timestamp(size_t i) const override { return timestamps_.at(i); }

  FrameData Load(size_t i) const override {
    if (i >= Size()) throw std::out_of_range("video frame index out of range");
    std::lock_guard<std::mutex> lock(mutex_);
    const cv::Mat* image = Recent(i);
    if (image == nullptr) {
      if (i < next_index_) Reopen();
      // Frames that could not be asked for again are only grabbed, the last kRecent decoded.
      while (next_index_ + kRecent <= i) {
        if (!capture_.grab()) ThrowDecodeError(next_index_);
        ++next_index_;
      }
      while (next_index_ <= i) Decode();
      image = Recent(i);
    }
    FrameData frame;
    frame.index = i;
    frame.timestamp = timestamps_[i];
    frame.name = "frame-" + std::to_string(i);
    frame.image = image->clone();
    return frame;
  }

 private:
  void Reopen() const {
    capture_.release();
    // FFmpeg when the build has it: deterministic frame order and no GStreamer console noise.
    const int api = cv::videoio_registry::hasBackend(cv::CAP_FFMPEG) ? cv::CAP_FFMPEG : cv::CAP_ANY;
    if (!capture_.open(file_.string(), api)) ThrowInputError(file_, "cannot open as a video");
    next_index_ = 0;
    recent_.clear();
  }
  const cv::Mat* Recent(size_t i) const {
    for (const auto& [index, image] : recent_) {
      if (index == i) return &image;
    }
    return nullptr;
  }
  // Reads frame next_index_ into the recent frames.
  void Decode() const {
    cv::Mat image;
    if (!capture_.read(image) || image.empty()) ThrowDecodeError(next_index_);
    cv::Mat bgr = ToBgr8(image, file_);
    if (bgr.cols != camera_.width || bgr.rows != camera_.height) {
      ThrowInputError(file_, "frames are " + std::to_string(bgr.cols) + "x" +
                                 std::to_string(bgr.rows) + ", the camera is " +
                                 std::to_string(camera_.width) + "x" +
                                 std::to_string(camera_.height));
    }
    if (recent_.size() == kRecent) recent_.pop_front();
    recent_.emplace_back(next_index_++, std::move(bgr));
  }
  [[noreturn]] void ThrowDecodeError(size_t i) const {
    ThrowInputError(file_, "frame " + std::to_string(i) + " does not decode");
  }

  fs::path file_;
  Camera camera_;
  std::vector<double> timestamps_;
  mutable std::mutex mutex_;
  mutable cv::VideoCapture capture_;
  mutable size_t next_index_ = 0;
  // More than the pipeline's workers can ask for out of order (--prefetch-frames at most 8).
  static constexpr size_t kRecent = 8;
  mutable std::deque<std::pair<size_t, cv::Mat>> recent_;
};

// A live camera. Frames are read in order by the real-time feed's capture thread; there is no
// going back, and the sequence never ends by itself (Ctrl-C ends the run).
class CameraSequence : public Sequence {
 public:
  CameraSequence(std::string device, Camera camera)
      : device_(std::move(device)), camera_(camera) {
    const bool is_index =
        !device_.empty() && device_.find_first_not_of("0123456789") == std::string::npos;
    bool opened = false;
    // OpenCV's backends log their own warnings for a missing device; the error below says it
    // once.
    const auto log_level = cv::utils::logging::getLogLevel();
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    // V4L2 when the build has it (Linux cameras): no GStreamer pipeline parsing of the path.
    const int api = cv::videoio_registry::hasBackend(cv::CAP_V4L2) ? cv::CAP_V4L2 : cv::CAP_ANY;
    try {
      opened = is_index && device_.size() < 6 ? capture_.open(std::stoi(device_), api)
                                              : capture_.open(device_, api);
    } catch (const std::exception&) {
      opened = false;
    }
    cv::utils::logging::setLogLevel(log_level);
    if (!opened || !capture_.isOpened())
      throw InputError("camera:" + device_ + ": cannot open the camera (no such device?)");
    capture_.set(cv::CAP_PROP_FRAME_WIDTH, camera_.width);
    capture_.set(cv::CAP_PROP_FRAME_HEIGHT, camera_.height);
    opened_ = std::chrono::steady_clock::now();
  }

  std::string Kind() const override { return "camera"; }
  fs::path Path() const override { return device_; }
  size_t Size() const override { return SIZE_MAX; }
  const Camera& GetCamera() const override { return camera_; }
  bool HasDepth() const override { return false; }
  bool HasGroundTruth() const override { return false; }
  double Timestamp(size_t) const override { return Seconds(); }

  FrameData Load(size_t i) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    cv::Mat image;
    if (!capture_.read(image) || image.empty())
      throw InputError("camera:" + device_ + ": frame " + std::to_string(i) +
                       " cannot be read (camera disconnected?)");
    FrameData frame;
    frame.index = i;
    frame.timestamp = Seconds();
    frame.name = "frame-" + std::to_string(i);
    frame.image = ToBgr8(image, device_);
    if (frame.image.cols != camera_.width || frame.image.rows != camera_.height) {
      throw InputError("camera:" + device_ + ": frames are " + std::to_string(frame.image.cols) +
                       "x" + std::to_string(frame.image.rows) + ", the camera YAML says " +
                       std::to_string(camera_.width) + "x" + std::to_string(camera_.height));
    }
    return frame;
  }

 private:
  double Seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - opened_).count();
  }
  std::string device_;
  Camera camera_;
  mutable std::mutex mutex_;
  mutable cv::VideoCapture capture_;
  std::chrono::steady_clock::time_point opened_;
};

}  // namespace

std::unique_ptr<Sequence> OpenCamera(const std::string& device,
                                     const std::optional<fs::path>& camera_yaml) {
  if (!camera_yaml) {
    throw InputError("camera:" + device + ": a live camera needs a camera YAML (--camera)");
  }
  return std::make_unique<CameraSequence>(device, LoadCameraYaml(*camera_yaml));
}

std::unique_ptr<Sequence> OpenVideo(const fs::path& file,
                                    const std::optional<fs::path>& camera_yaml) {
  RequireFile(file);
  std::optional<Camera> beside;
  const fs::path beside_yaml = file.parent_path() / "camera.yaml";
  if (fs::exists(beside_yaml)) beside = LoadCameraYaml(beside_yaml);
  const Camera camera = ResolveCamera(
      camera_yaml, beside, file, "a video needs a camera YAML (--camera or camera.yaml beside it)");
  return std::make_unique<VideoSequence>(file, camera);
}

}  // namespace ademono
