#include "ademono/depth/cache_depth.h"

#include <cmath>
#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"

namespace ademono {
namespace {

bool IsDepthExtension(const std::string& ext) {
  return ext == ".png" || ext == ".tif" || ext == ".tiff";
}

// The last number in a file stem ("1305031102.175304", "depth_000012.5"), if the stem holds one.
bool ParseStemTimestamp(const std::string& stem, double* value) {
  size_t end = stem.size();
  while (end > 0 && !(std::isdigit(static_cast<unsigned char>(stem[end - 1])))) --end;
  if (end == 0) return false;
  size_t begin = end;
  while (begin > 0 &&
         (std::isdigit(static_cast<unsigned char>(stem[begin - 1])) || stem[begin - 1] == '.')) {
    --begin;
  }
  while (begin < end && stem[begin] == '.') ++begin;
  const std::string text = stem.substr(begin, end - begin);
  if (text.empty()) return false;
  char* parse_end = nullptr;
  *value = std::strtod(text.c_str(), &parse_end);
  return parse_end != nullptr && *parse_end == '\0' && std::isfinite(*value);
}

}  // namespace

cv::Mat ReadDepthMap(const std::filesystem::path& path) {
  const char* expected = "depth map must be 16-bit PNG (mm) or 32-bit float TIFF (m)";
  // Only the two documented formats reach a decoder.
  const cv::Mat raw =
      ReadImage(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR,
                {ImageFormat::kPng, ImageFormat::kTiff, ImageFormat::kBigTiff}, expected);
  if (raw.channels() != 1) ThrowInputError(path, "depth map must have one channel");
  cv::Mat depth(raw.size(), CV_32FC1);
  if (raw.depth() == CV_16U) {
    for (int y = 0; y < raw.rows; ++y) {
      const uint16_t* in = raw.ptr<uint16_t>(y);
      float* out = depth.ptr<float>(y);
      for (int x = 0; x < raw.cols; ++x) {
        out[x] = (in[x] == 0 || in[x] == 65535) ? 0.f : in[x] * 0.001f;
      }
    }
  } else if (raw.depth() == CV_32F) {
    for (int y = 0; y < raw.rows; ++y) {
      const float* in = raw.ptr<float>(y);
      float* out = depth.ptr<float>(y);
      for (int x = 0; x < raw.cols; ++x)
        out[x] = (std::isfinite(in[x]) && in[x] > 0.f) ? in[x] : 0.f;
    }
  } else {
    ThrowInputError(path, expected);
  }
  return depth;
}

CacheDepthProvider::CacheDepthProvider(const std::filesystem::path& dir) : dir_(dir) {
  RequireDirectory(dir);
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const std::string ext = entry.path().extension().string();
    if (!IsDepthExtension(ext)) continue;
    std::string stem = entry.path().stem().string();
    by_stem_.emplace(stem, entry.path());
    // "frame-000001.depth.png" also answers to the image stem "frame-000001.color".
    const std::string suffix = ".depth";
    if (stem.size() > suffix.size() && stem.ends_with(suffix)) {
      by_stem_.emplace(stem.substr(0, stem.size() - suffix.size()), entry.path());
    }
    double t = 0;
    if (ParseStemTimestamp(stem, &t)) by_time_.emplace(t, entry.path());
  }
  if (by_stem_.empty()) ThrowInputError(dir, "no depth maps (.png, .tif, .tiff) in the folder");
}

std::filesystem::path CacheDepthProvider::FindFile(const FrameData& frame) const {
  std::vector<std::string> candidates{frame.name};
  // Image stems like "frame-000001.color" map to "frame-000001" and "frame-000001.depth".
  const size_t dot = frame.name.rfind('.');
  if (dot != std::string::npos) candidates.push_back(frame.name.substr(0, dot));
  for (const auto& stem : candidates) {
    if (stem.empty()) continue;
    if (auto it = by_stem_.find(stem); it != by_stem_.end()) return it->second;
    if (auto it = by_stem_.find(stem + ".depth"); it != by_stem_.end()) return it->second;
  }
  constexpr double kTimeTolerance = 1e-3;
  auto it = by_time_.lower_bound(frame.timestamp - kTimeTolerance);
  if (it != by_time_.end() && std::abs(it->first - frame.timestamp) <= kTimeTolerance) {
    return it->second;
  }
  return {};
}

cv::Mat CacheDepthProvider::Depth(const FrameData& frame, const Camera& camera) {
  const std::filesystem::path file = FindFile(frame);
  if (file.empty()) {
    char stamp[64];
    std::snprintf(stamp, sizeof(stamp), "%.6f", frame.timestamp);
    ThrowInputError(dir_, "no cached depth map for frame " + std::to_string(frame.index) + " ('" +
                              frame.name + "', t=" + stamp + ")");
  }
  cv::Mat depth = ReadDepthMap(file);
  const int width = frame.image.empty() ? camera.width : frame.image.cols;
  const int height = frame.image.empty() ? camera.height : frame.image.rows;
  if (width > 0 && height > 0 && (depth.cols != width || depth.rows != height)) {
    cv::Mat resized;
    cv::resize(depth, resized, cv::Size(width, height), 0, 0, cv::INTER_NEAREST);
    depth = resized;
  }
  return depth;
}

}  // namespace ademono
