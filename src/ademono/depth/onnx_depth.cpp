#include "ademono/depth/onnx_depth.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/dnn/model_arg.h"

namespace ademono {

namespace {

// A depth map covers the network input: its aspect ratio, at the input's resolution or a
// fraction of it (10 % slack for rounding at odd sizes). Anything else, e.g. a detector's head
// loaded as a depth model, is the wrong kind of model.
bool CoversTheInput(int64_t in_h, int64_t in_w, int64_t out_h, int64_t out_w) {
  const double sx = static_cast<double>(out_w) / static_cast<double>(in_w);
  const double sy = static_cast<double>(out_h) / static_cast<double>(in_h);
  return std::max(sx, sy) <= 1.1 * std::min(sx, sy);
}

}  // namespace
std::optional<std::filesystem::path> FindModelSpecFile(
    const std::filesystem::path& model_path, const std::optional<std::filesystem::path>& given) {
  if (given) return given;
  auto sibling = model_path;
  sibling.replace_extension(".yaml");
  if (std::filesystem::is_regular_file(sibling)) return sibling;
  return std::nullopt;
}

DepthSourceInfo DescribeModelDepth(const std::string& argument) {
  const ModelArg model = ParseModelArg(argument, {"spec"});
  std::optional<std::filesystem::path> spec;
  if (auto it = model.options.find("spec"); it != model.options.end()) spec = it->second;
  DepthSourceInfo info;
  info.network = true;
  if (const auto file = FindModelSpecFile(model.file, spec)) {
    const DepthModelSpec loaded = DepthModelSpec::Load(*file);
    info.domain = loaded.domain;
    info.error_model = loaded.uncertainty;
  }
  return info;
}

OnnxDepthProvider::OnnxDepthProvider(const std::filesystem::path& model_path,
                                     const std::optional<std::filesystem::path>& spec_path,
                                     const OrtSessionOptions& session_options) {
  const std::optional<std::filesystem::path> spec_file = FindModelSpecFile(model_path, spec_path);
  if (spec_file) {
    spec_ = DepthModelSpec::Load(*spec_file);
    spec_source_ = spec_file->string();
  } else {
    spec_source_ = "default spec";
  }
  session_ = std::make_unique<OrtSession>(model_path, session_options);

  const auto& in = session_->Inputs()[0].shape;
  const std::string in_text = ShapeToString(in);
  if (in.size() != 4 || (in[0] != 1 && in[0] != -1) || (in[1] != 3 && in[1] != -1)) {
    ThrowInputError(model_path, "depth model input must be 1x3xHxW, the model has " + in_text);
  }
  const bool fixed_size = in[2] > 0 && in[3] > 0;
  if (spec_.resize == DepthModelSpec::Resize::kMultiple) {
    if (fixed_size) {
      ThrowInputError(model_path, "model input " + in_text + " has a fixed size but the spec (" +
                                      spec_source_ +
                                      ") asks for resize: multiple; use fixed or letterbox");
    }
  } else if (spec_.width == 0) {
    if (!fixed_size) {
      ThrowInputError(model_path, "model input " + in_text + " has a dynamic size: the spec (" +
                                      spec_source_ + ") must give input.width and input.height");
    }
    spec_.width = static_cast<int>(in[3]);
    spec_.height = static_cast<int>(in[2]);
  } else if ((in[2] > 0 && in[2] != spec_.height) || (in[3] > 0 && in[3] != spec_.width)) {
    ThrowInputError(model_path, "model input " + in_text + " does not match the spec (" +
                                    spec_source_ + ") input " + std::to_string(spec_.width) + "x" +
                                    std::to_string(spec_.height) + " (width x height)");
  }
  const auto& out = session_->Outputs()[0].shape;
  const std::string out_text = ShapeToString(out);
  bool out_ok = out.size() >= 2 && out.size() <= 4;
  for (size_t i = 0; out_ok && i + 2 < out.size(); ++i) out_ok = out[i] == 1 || out[i] == -1;
  if (out_ok && fixed_size && out[out.size() - 2] > 0 && out[out.size() - 1] > 0) {
    out_ok = CoversTheInput(in[2], in[3], out[out.size() - 2], out[out.size() - 1]);
  }
  if (!out_ok) {
    ThrowInputError(model_path,
                    "depth model output must be 1x1xHxW, 1xHxW or HxW with the input's aspect "
                    "ratio, the model has " + out_text + " (input " + in_text + ")");
  }
  if (session_->Outputs().size() > 1) {
    spdlog::debug("{}: using the first of {} outputs", model_path.string(),
                  session_->Outputs().size());
  }
  if (!spec_path && !spec_file) {
    spdlog::warn(
        "{}: no spec given and no {} beside it: assuming RGB ImageNet normalisation and "
        "metric output",
        model_path.string(), model_path.stem().string() + ".yaml");
  }
}

std::string OnnxDepthProvider::Name() const {
  return "model:" + session_->Path().string() + " (" + spec_.name + ")";
}

cv::Mat OnnxDepthProvider::Depth(const FrameData& frame, const Camera& camera) {
  return DepthFromImage(frame.image, camera);
}

cv::Mat OnnxDepthProvider::DepthFromImage(const cv::Mat& image, const Camera& camera) const {
  if (image.empty()) throw std::invalid_argument("OnnxDepthProvider: empty image");
  cv::Size input_size, content_size;
  spec_.InputGeometry(image.size(), &input_size, &content_size);
  ResizeTransform transform;
  const cv::Mat input = ResizeAndPad(
      image, content_size, input_size, spec_.pad,
      // pad_value is in the network's colour order; the image is BGR until ImageToBlob.
      spec_.rgb ? cv::Scalar(spec_.pad_value[2], spec_.pad_value[1], spec_.pad_value[0])
                : cv::Scalar(spec_.pad_value[0], spec_.pad_value[1], spec_.pad_value[2]),
      spec_.interpolation, &transform);
  const auto blob = ImageToBlob(input, spec_.rgb, spec_.mean, spec_.std);
  const auto outputs = session_->Run(blob, {1, 3, input_size.height, input_size.width});
  const Tensor& out = outputs[0];
  if (out.shape.size() < 2) {
    ThrowInputError(session_->Path(), "output has shape " + ShapeToString(out.shape));
  }
  const int out_h = static_cast<int>(out.shape[out.shape.size() - 2]);
  const int out_w = static_cast<int>(out.shape[out.shape.size() - 1]);
  if (static_cast<size_t>(out_h) * out_w != out.data.size()) {
    ThrowInputError(session_->Path(),
                    "output " + ShapeToString(out.shape) + " is not a single depth map");
  }
  if (!CoversTheInput(input_size.height, input_size.width, out_h, out_w)) {
    ThrowInputError(session_->Path(), "output " + ShapeToString(out.shape) +
                                          " does not have the aspect ratio of the input " +
                                          std::to_string(input_size.width) + "x" +
                                          std::to_string(input_size.height));
  }
  const cv::Mat raw(out_h, out_w, CV_32F, const_cast<float*>(out.data.data()));
  // The padding, in output pixels (outputs may be at a fraction of the input resolution).
  const double sx = static_cast<double>(out_w) / input_size.width;
  const double sy = static_cast<double>(out_h) / input_size.height;
  const int x0 = static_cast<int>(std::lround(transform.content.x * sx));
  const int y0 = static_cast<int>(std::lround(transform.content.y * sy));
  const int x1 = static_cast<int>(std::lround(transform.content.br().x * sx));
  const int y1 = static_cast<int>(std::lround(transform.content.br().y * sy));
  const cv::Rect crop = cv::Rect(x0, y0, x1 - x0, y1 - y0) & cv::Rect(0, 0, out_w, out_h);
  if (crop.area() <= 0) {
    ThrowInputError(session_->Path(), "output " + ShapeToString(out.shape) +
                                          " leaves nothing after removing the padding");
  }
  cv::Mat resized;
  cv::resize(raw(crop), resized, image.size(), 0, 0, cv::INTER_LINEAR);

  double focal_scale = 1.0;
  if (spec_.canonical_focal > 0) {
    const double fx_image = camera.width > 0 ? camera.fx * image.cols / camera.width : camera.fx;
    if (!(fx_image > 0)) throw std::invalid_argument("canonical-focal depth model needs fx > 0");
    focal_scale = fx_image * transform.scale_x / spec_.canonical_focal;
  }
  // disparity_width: fx / W is the same at any resolution of the camera's image.
  double focal_over_width = 0.0;
  if (spec_.kind == DepthModelSpec::Kind::kDisparityWidth) {
    focal_over_width = camera.width > 0 ? camera.fx / camera.width : 0.0;
    if (!(focal_over_width > 0)) {
      throw std::invalid_argument("disparity_width depth model needs the camera's fx and width");
    }
  }
  cv::Mat depth(image.size(), CV_32F);
  for (int r = 0; r < depth.rows; ++r) {
    const float* y = resized.ptr<float>(r);
    float* d = depth.ptr<float>(r);
    for (int c = 0; c < depth.cols; ++c) {
      const double value = spec_.ToDepth(y[c], focal_scale, focal_over_width);
      d[c] =
          std::isfinite(value) && value >= spec_.min_depth && value <= spec_.max_depth && value > 0
              ? static_cast<float>(value)
              : 0.f;
    }
  }
  return depth;
}

cv::Mat DepthToMillimetres(const cv::Mat& depth_m) {
  CV_Assert(depth_m.type() == CV_32FC1);
  cv::Mat mm(depth_m.size(), CV_16UC1);
  for (int r = 0; r < depth_m.rows; ++r) {
    const float* d = depth_m.ptr<float>(r);
    uint16_t* out = mm.ptr<uint16_t>(r);
    for (int c = 0; c < depth_m.cols; ++c) {
      const double value = std::round(static_cast<double>(d[c]) * 1000.0);
      out[c] =
          std::isfinite(value) && value > 0 && value < 65535 ? static_cast<uint16_t>(value) : 0;
    }
  }
  return mm;
}

void WriteDepthMap(const std::filesystem::path& path, const cv::Mat& depth_m) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (ext == ".png") {
    WriteImageAtomic(path, DepthToMillimetres(depth_m));
  } else if (ext == ".tif" || ext == ".tiff") {
    WriteImageAtomic(path, depth_m);
  } else {
    ThrowInputError(path, "depth output must be .png (uint16 mm) or .tif/.tiff (float m)");
  }
}

cv::Mat ColouriseDepth(const cv::Mat& depth_m) {
  CV_Assert(depth_m.type() == CV_32FC1);
  std::vector<float> valid;
  for (int r = 0; r < depth_m.rows; ++r) {
    const float* d = depth_m.ptr<float>(r);
    for (int c = 0; c < depth_m.cols; ++c) {
      if (d[c] > 0 && std::isfinite(d[c])) valid.push_back(d[c]);
    }
  }
  cv::Mat preview(depth_m.size(), CV_8UC3, cv::Scalar::all(0));
  if (valid.empty()) return preview;
  auto percentile = [&](double q) {
    const size_t k = static_cast<size_t>(q * (valid.size() - 1));
    std::nth_element(valid.begin(), valid.begin() + k, valid.end());
    return valid[k];
  };
  const float lo = percentile(0.02), hi = std::max(percentile(0.98), lo + 1e-3f);
  cv::Mat gray(depth_m.size(), CV_8UC1);
  for (int r = 0; r < depth_m.rows; ++r) {
    const float* d = depth_m.ptr<float>(r);
    uint8_t* g = gray.ptr<uint8_t>(r);
    for (int c = 0; c < depth_m.cols; ++c) {
      // Near = 255 (red end of turbo).
      g[c] = cv::saturate_cast<uint8_t>(255.0 * (hi - std::clamp(d[c], lo, hi)) / (hi - lo));
    }
  }
  cv::applyColorMap(gray, preview, cv::COLORMAP_TURBO);
  preview.setTo(cv::Scalar::all(0), depth_m <= 0);
  return preview;
}

std::unique_ptr<DepthProvider> MakeOnnxDepthProvider(const std::string& argument,
                                                     const DepthFactoryContext& context) {
  const ModelArg model = ParseModelArg(argument, {"spec"});
  std::optional<std::filesystem::path> spec;
  if (auto it = model.options.find("spec"); it != model.options.end()) spec = it->second;
  OrtSessionOptions options;
  options.intra_op_threads = context.num_threads;
  try {
    options.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  return std::make_unique<OnnxDepthProvider>(model.file, spec, options);
}

}  // namespace ademono
