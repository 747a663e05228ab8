#pragma once
// Metric depth from an ONNX model (`--depth model:FILE.onnx[,spec=SPEC.yaml]`).
//
// The spec (model_spec.h) says how to resize, pad and normalise the image and how to turn the
// output into metres. Without spec=, `<model stem>.yaml` beside the model is used if present,
// else the defaults (model's fixed size, stretch, RGB ImageNet normalisation, metric output).
// The model is checked against the spec at load: input 1x3xHxW (H, W fixed for resize fixed /
// letterbox and equal to the spec's size; dynamic for resize multiple), output 1x1xhxw, 1xhxw or
// hxw. A mismatch throws InputError naming the model file and both shapes.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "ademono/depth/depth_factory.h"
#include "ademono/depth/depth_provider.h"
#include "ademono/depth/model_spec.h"
#include "ademono/dnn/ort_session.h"

namespace ademono {

class OnnxDepthProvider : public DepthProvider {
 public:
  OnnxDepthProvider(const std::filesystem::path& model_path,
                    const std::optional<std::filesystem::path>& spec_path,
                    const OrtSessionOptions& session_options);
  std::string Name() const override;
  cv::Mat Depth(const FrameData& frame, const Camera& camera) override;
  // CV_32FC1 metres at the image's size, 0 where invalid. `camera` gives fx for canonical-focal
  // models; its intrinsics are rescaled if the image size differs from the camera's.
  cv::Mat DepthFromImage(const cv::Mat& image, const Camera& camera) const;

  const DepthModelSpec& Spec() const { return spec_; }
  const OrtSession& Session() const { return *session_; }

 private:
  std::unique_ptr<OrtSession> session_;
  DepthModelSpec spec_;
  std::string spec_source_;
};

// Depth map files written by `ademono depth` / `ademono infer` (read back by cache:DIR):
// ".png": uint16 millimetres, 0 = invalid (depths beyond 65.534 m are written as invalid);
// ".tif"/".tiff": float32 metres. Written atomically. InputError for another extension.
void WriteDepthMap(const std::filesystem::path& path, const cv::Mat& depth_m);
cv::Mat DepthToMillimetres(const cv::Mat& depth_m);
// BGR preview: turbo colour map over the 2nd..98th percentile of the valid depths (near = red),
// invalid pixels black.
cv::Mat ColouriseDepth(const cv::Mat& depth_m);

// The spec file of a model: `given`, else `<model stem>.yaml` beside it if present.
std::optional<std::filesystem::path> FindModelSpecFile(
    const std::filesystem::path& model_path, const std::optional<std::filesystem::path>& given);
// What the spec of `model:ARGUMENT` says of the depth (domain, error model), without loading the
// network. InputError for a bad argument or spec.
DepthSourceInfo DescribeModelDepth(const std::string& argument);

// The `model:` branch of MakeDepthProvider: `argument` is "FILE.onnx[,spec=SPEC.yaml]".
std::unique_ptr<DepthProvider> MakeOnnxDepthProvider(const std::string& argument,
                                                     const DepthFactoryContext& context);

}  // namespace ademono
