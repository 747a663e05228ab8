#include "ademono/depth/simulated_depth.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/depth/cache_depth.h"

namespace ademono {

namespace {

uint64_t Mix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

[[noreturn]] void BadSpec(const std::string& message) {
  throw InputError("depth provider 'simulated': " + message);
}

double ParseNumber(const std::string& key, const std::string& value) {
  double out = 0.0;
  const auto result = std::from_chars(value.data(), value.data() + value.size(), out);
  if (result.ec != std::errc() || result.ptr != value.data() + value.size() || !std::isfinite(out))
    BadSpec("'" + key + "=" + value + "' is not a number");
  return out;
}

// Zero-mean, unit-variance smooth field: Gaussian values on a coarse grid (one per `cell` px),
// cubic upsampling, normalised by its own spread.
cv::Mat SmoothField(cv::Size size, cv::RNG& rng, int cell) {
  cv::Mat coarse(size.height / cell + 3, size.width / cell + 3, CV_32F);
  rng.fill(coarse, cv::RNG::NORMAL, 0.0, 1.0);
  cv::Mat field;
  cv::resize(coarse, field, size, 0, 0, cv::INTER_CUBIC);
  cv::Scalar mean, stddev;
  cv::meanStdDev(field, mean, stddev);
  field = (field - mean[0]) / std::max(1e-6, stddev[0]);
  return field;
}

}  // namespace

void SimulatedDepthOptions::Check() const {
  if (!(scale > 0.0) || !std::isfinite(scale)) throw std::invalid_argument("scale must be > 0");
  if (!(a >= 0.0) || !std::isfinite(a)) throw std::invalid_argument("a must be >= 0");
  if (!(b >= 0.0) || !std::isfinite(b)) throw std::invalid_argument("b must be >= 0");
  if (edge_blur < 0 || edge_blur > 50) throw std::invalid_argument("edge_blur must be in [0, 50]");
  if (!(invalid >= 0.0 && invalid < 1.0)) throw std::invalid_argument("invalid must be in [0, 1)");
  if (!(pixel >= 0.0 && pixel <= 1.0)) throw std::invalid_argument("pixel must be in [0, 1]");
  if (!(jitter >= 0.0 && jitter <= 1.0)) throw std::invalid_argument("jitter must be in [0, 1]");
  if (!(jitter_frames >= 1.0) || !std::isfinite(jitter_frames))
    throw std::invalid_argument("jitter_frames must be >= 1");
  if (!std::isfinite(shift) || std::abs(shift) > 10.0)
    throw std::invalid_argument("shift must be in [-10, 10]");
  if (!(shift_jitter >= 0.0 && shift_jitter <= 10.0))
    throw std::invalid_argument("shift_jitter must be in [0, 10]");
}

SimulatedDepthOptions SimulatedDepthOptions::Parse(const std::string& argument,
                                                   uint64_t default_seed) {
  SimulatedDepthOptions options;
  options.seed = default_seed;
  size_t start = 0;
  while (start < argument.size()) {
    size_t end = argument.find(',', start);
    if (end == std::string::npos) end = argument.size();
    const std::string item = argument.substr(start, end - start);
    start = end + 1;
    if (item.empty()) continue;
    const size_t eq = item.find('=');
    if (eq == std::string::npos) BadSpec("'" + item + "' is not key=value");
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "scale") {
      options.scale = ParseNumber(key, value);
    } else if (key == "a") {
      options.a = ParseNumber(key, value);
    } else if (key == "b") {
      options.b = ParseNumber(key, value);
    } else if (key == "invalid") {
      options.invalid = ParseNumber(key, value);
    } else if (key == "pixel") {
      options.pixel = ParseNumber(key, value);
    } else if (key == "jitter") {
      options.jitter = ParseNumber(key, value);
    } else if (key == "jitter_frames") {
      options.jitter_frames = ParseNumber(key, value);
    } else if (key == "shift") {
      options.shift = ParseNumber(key, value);
    } else if (key == "shift_jitter") {
      options.shift_jitter = ParseNumber(key, value);
    } else if (key == "edge_blur" || key == "seed") {
      const double number = ParseNumber(key, value);
      if (number < 0 || number != std::floor(number) || number > 1.8e19)
        BadSpec("'" + item + "' must be a non-negative integer");
      if (key == "seed") {
        uint64_t seed = 0;
        std::from_chars(value.data(), value.data() + value.size(), seed);
        options.seed = seed;
      } else {
        options.edge_blur = number > 1000 ? 1000 : static_cast<int>(number);
      }
    } else if (key == "gt") {
      if (value.empty()) BadSpec("gt= needs a folder");
      options.gt_dir = value;
    } else {
      BadSpec("unknown parameter '" + key +
              "' (expected scale, a, b, pixel, edge_blur, invalid, jitter, jitter_frames, shift, "
              "shift_jitter, seed, gt)");
    }
  }
  try {
    options.Check();
  } catch (const std::invalid_argument& e) {
    BadSpec(e.what());
  }
  return options;
}

SimulatedDepthProvider::SimulatedDepthProvider(const SimulatedDepthOptions& options,
                                               std::unique_ptr<DepthProvider> ground_truth)
    : options_(options), ground_truth_(std::move(ground_truth)) {
  options_.Check();
}

cv::Mat SimulatedDepthProvider::Depth(const FrameData& frame, const Camera& camera) {
  cv::Mat truth;
  if (ground_truth_) {
    truth = ground_truth_->Depth(frame, camera);
  } else {
    if (frame.depth.empty())
      throw InputError("frame '" + frame.name +
                       "' has no ground-truth depth for the simulated "
                       "depth provider (use a dataset with depth, or simulated:gt=DIR)");
    truth = frame.depth;
  }
  if (truth.type() != CV_32FC1)
    throw InputError("frame '" + frame.name + "': ground-truth depth is not CV_32FC1");
  if (!frame.image.empty() && truth.size() != frame.image.size())
    throw InputError("frame '" + frame.name + "': depth size differs from the image size");
  return Degrade(truth, frame.index);
}

namespace {

constexpr int kTerms = 8;

// A smooth zero-mean signal of the frame index, of variance kTerms / 2: a sum of kTerms cosines
// with periods around `frames` and phases from `seed` only.
double CosineSum(uint64_t seed, double frames, size_t frame_index) {
  cv::RNG rng(Mix64(seed) | 1);
  const double two_pi = 2.0 * 3.14159265358979323846;
  double sum = 0.0;
  for (int m = 0; m < kTerms; ++m) {
    const double period = frames * std::exp(rng.uniform(-0.7, 0.7));
    const double phase = rng.uniform(0.0, two_pi);
    sum += std::cos(two_pi * static_cast<double>(frame_index) / period + phase);
  }
  return sum;
}

}  // namespace

double SimulatedDepthProvider::FrameScale(size_t frame_index) const {
  if (options_.jitter <= 0.0) return options_.scale;
  // Periods and phases depend on the seed only, so the signal is a function of the frame index.
  const double sum = CosineSum(options_.seed ^ 0x5CA1E, options_.jitter_frames, frame_index);
  return options_.scale * std::exp(options_.jitter * std::sqrt(2.0 / kTerms) * sum);
}

double SimulatedDepthProvider::FrameShift(size_t frame_index) const {
  if (options_.shift_jitter <= 0.0) return options_.shift;
  const double sum = CosineSum(options_.seed ^ 0x5A1F7, options_.jitter_frames, frame_index);
  return options_.shift + options_.shift_jitter * std::sqrt(2.0 / kTerms) * sum;
}

cv::Mat SimulatedDepthProvider::Degrade(const cv::Mat& depth_m, size_t frame_index) const {
  CV_Assert(depth_m.type() == CV_32FC1);
  const cv::Size size = depth_m.size();
  cv::Mat valid = depth_m > 0.f;  // 255 / 0; NaN compares false
  cv::Mat truth;
  depth_m.copyTo(truth);
  truth.setTo(0.f, ~valid);

  // Depth edges: smear over `edge_blur` pixels where the local depth ratio is large.
  cv::Mat edged = truth.clone();
  if (options_.edge_blur > 0) {
    const int k = 2 * options_.edge_blur + 1;
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, {k, k});
    cv::Mat high, low, sentinel = truth.clone();
    sentinel.setTo(1e9f, ~valid);  // invalid pixels must not become the local minimum
    cv::dilate(truth, high, kernel);
    cv::erode(sentinel, low, kernel);
    cv::Mat weights, sums;
    cv::Mat valid_f;
    valid.convertTo(valid_f, CV_32F, 1.0 / 255.0);
    cv::boxFilter(truth, sums, CV_32F, {k, k}, {-1, -1}, false, cv::BORDER_REPLICATE);
    cv::boxFilter(valid_f, weights, CV_32F, {k, k}, {-1, -1}, false, cv::BORDER_REPLICATE);
    for (int v = 0; v < size.height; ++v) {
      const float* h = high.ptr<float>(v);
      const float* l = low.ptr<float>(v);
      const float* s = sums.ptr<float>(v);
      const float* w = weights.ptr<float>(v);
      const uint8_t* ok = valid.ptr<uint8_t>(v);
      float* out = edged.ptr<float>(v);
      for (int u = 0; u < size.width; ++u) {
        if (ok[u] && h[u] > 1.1f * l[u] && w[u] > 0.f) out[u] = s[u] / w[u];
      }
    }
  }

  // Noise drawn from (seed, frame) only: same frame, same maps, whatever the thread.
  cv::RNG rng(Mix64(options_.seed ^ Mix64(frame_index + 0x51D)) | 1);
  const cv::Mat smooth = SmoothField(size, rng, 32);
  cv::Mat pixel(size, CV_32F);
  rng.fill(pixel, cv::RNG::NORMAL, 0.0, 1.0);
  // Invalid pixels come in blobs (where a network's confidence is low), not as salt noise:
  // the top `invalid` fraction of another smooth field.
  const cv::Mat holes = SmoothField(size, rng, 12);
  float hole_threshold = std::numeric_limits<float>::infinity();
  if (options_.invalid > 0.0) {
    std::vector<float> values(holes.begin<float>(), holes.end<float>());
    const size_t k =
        std::min(values.size() - 1,
                 static_cast<size_t>(std::floor((1.0 - options_.invalid) * values.size())));
    std::nth_element(values.begin(), values.begin() + k, values.end());
    hole_threshold = values[k];
  }

  const double frame_scale = FrameScale(frame_index);
  const double frame_shift = FrameShift(frame_index);
  const float smooth_weight = static_cast<float>(std::sqrt(1.0 - options_.pixel));
  const float pixel_weight = static_cast<float>(std::sqrt(options_.pixel));
  cv::Mat out(size, CV_32F);
  for (int v = 0; v < size.height; ++v) {
    const float* z_true = truth.ptr<float>(v);
    const float* z_edge = edged.ptr<float>(v);
    const float* ns = smooth.ptr<float>(v);
    const float* np = pixel.ptr<float>(v);
    const float* hole = holes.ptr<float>(v);
    float* o = out.ptr<float>(v);
    for (int u = 0; u < size.width; ++u) {
      const double z = z_true[u];
      if (!(z > 0.0) || hole[u] >= hole_threshold) {
        o[u] = 0.f;
        continue;
      }
      const double sigma = options_.a * z + options_.b * z * z;
      double noisy =
          frame_scale * (z_edge[u] + sigma * (smooth_weight * ns[u] + pixel_weight * np[u]));
      if (frame_shift != 0.0 && noisy > 0.0) {
        const double inverse = 1.0 / noisy + frame_shift;
        noisy = inverse > 0.0 ? 1.0 / inverse : 0.0;
      }
      o[u] = noisy > 0.0 ? static_cast<float>(noisy) : 0.f;
    }
  }
  return out;
}

std::unique_ptr<DepthProvider> MakeSimulatedDepthProvider(const std::string& argument,
                                                          const DepthFactoryContext& context) {
  const SimulatedDepthOptions options = SimulatedDepthOptions::Parse(argument, context.seed);
  std::unique_ptr<DepthProvider> ground_truth;
  if (options.gt_dir) {
    ground_truth = std::make_unique<CacheDepthProvider>(*options.gt_dir);
  } else if (context.sequence && !context.sequence->HasDepth()) {
    throw InputError("depth provider 'simulated' needs ground-truth depth, and the dataset " +
                     context.sequence->Path().string() +
                     " has none (give simulated:gt=DIR with depth maps)");
  }
  return std::make_unique<SimulatedDepthProvider>(options, std::move(ground_truth));
}

}  // namespace ademono
