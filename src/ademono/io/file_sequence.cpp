#include "ademono/io/file_sequence.h"

#include <algorithm>
#include <cctype>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"

namespace fs = std::filesystem;

namespace ademono {

FileSequence::FileSequence(FileSequenceSpec spec) : spec_(std::move(spec)) {
  if (spec_.frames.empty()) ThrowInputError(spec_.path, "sequence has no frames");
}

double FileSequence::Timestamp(size_t i) const { return spec_.frames.at(i).timestamp; }

FrameData FileSequence::LoadFrame(size_t i, bool with_depth) const {
  const FileFrame& f = spec_.frames.at(i);
  FrameData frame;
  frame.index = i;
  frame.timestamp = f.timestamp;
  frame.name = f.image.stem().string();
  frame.image = ToBgr8(ReadImage(f.image, cv::IMREAD_UNCHANGED), f.image);
  const cv::Size expected(spec_.camera.width, spec_.camera.height);
  if (frame.image.size() != expected) {
    ThrowInputError(f.image, "image is " + std::to_string(frame.image.cols) + "x" +
                                 std::to_string(frame.image.rows) + ", the camera is " +
                                 std::to_string(expected.width) + "x" +
                                 std::to_string(expected.height));
  }
  if (with_depth) frame.depth = FileSequence::LoadDepth(i);
  frame.world_from_cam_gt = f.world_from_cam_gt;
  return frame;
}

cv::Mat FileSequence::LoadDepth(size_t i) const {
  const FileFrame& f = spec_.frames.at(i);
  if (f.depth.empty()) return {};
  cv::Mat depth =
      DepthToMetres(ReadImage(f.depth, cv::IMREAD_UNCHANGED), spec_.depth_scale, f.depth);
  // The colour image is the camera's size (LoadFrame checks it first).
  if (depth.size() != cv::Size(spec_.camera.width, spec_.camera.height)) {
    ThrowInputError(f.depth, "depth image size differs from the colour image size");
  }
  return depth;
}

cv::Mat ToBgr8(const cv::Mat& image, const fs::path& path) {
  cv::Mat eight_bit = image;
  if (image.depth() == CV_16U) {
    image.convertTo(eight_bit, CV_8U, 1.0 / 257.0);
  } else if (image.depth() != CV_8U) {
    ThrowInputError(path, "unsupported image pixel type (expected 8 or 16 bit)");
  }
  cv::Mat bgr;
  switch (eight_bit.channels()) {
    case 1:
      cv::cvtColor(eight_bit, bgr, cv::COLOR_GRAY2BGR);
      break;
    case 3:
      bgr = eight_bit;
      break;
    case 4:
      cv::cvtColor(eight_bit, bgr, cv::COLOR_BGRA2BGR);
      break;
    default:
      ThrowInputError(
          path, "unsupported number of image channels " + std::to_string(eight_bit.channels()));
  }
  return bgr;
}

cv::Mat DepthToMetres(const cv::Mat& raw, double scale, const fs::path& path) {
  if (raw.type() != CV_16UC1) {
    ThrowInputError(path, "depth image must be single-channel 16-bit");
  }
  cv::Mat metres(raw.size(), CV_32FC1);
  for (int r = 0; r < raw.rows; ++r) {
    const uint16_t* in = raw.ptr<uint16_t>(r);
    float* out = metres.ptr<float>(r);
    for (int c = 0; c < raw.cols; ++c) {
      const uint16_t v = in[c];
      out[c] = (v == 0 || v == 65535) ? 0.0f : static_cast<float>(v * scale);
    }
  }
  return metres;
}

cv::Size ImageSizeOf(const fs::path& path) {
  const cv::Mat image = ReadImage(path, cv::IMREAD_UNCHANGED);
  return image.size();
}

Camera ResolveCamera(const std::optional<fs::path>& camera_yaml,
                     const std::optional<Camera>& fallback, const fs::path& where,
                     const std::string& why) {
  if (camera_yaml) return LoadCameraYaml(*camera_yaml);
  if (fallback) return *fallback;
  ThrowInputError(where, why);
}

bool IsImageFile(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" ||
         ext == ".tiff" || ext == ".ppm" || ext == ".pgm" || ext == ".webp";
}

}  // namespace ademono
