#pragma once
// How to feed a metric-depth ONNX model and read its output: the model spec YAML
// (configs/models/*.yaml, documented in docs/models.md).
//
//   name: depth_anything_v2_metric_indoor
//   input:
//     resize: fixed        # fixed:     stretch to width x height (aspect not kept)
//                          # letterbox: keep aspect, fit inside width x height, pad the rest
//                          # multiple:  keep aspect, scale so the long (or short) side is
//                          #            `side_length` (0 = native size), pad each side up to a
//                          #            multiple of `multiple_of` (dynamic-size models)
//     width: 518           # fixed / letterbox
//     height: 518
//     side: long           # multiple: which side gets side_length (long | short)
//     side_length: 518
//     multiple_of: 14
//     pad: centre          # letterbox / multiple: centre | bottom_right; multiple also takes
//                          # none: round each side to the nearest multiple instead of padding
//                          # (slight stretch, as Depth Anything does; never below side_length
//                          # for side: short)
//     pad_value: [0, 0, 0] # 0..255 units, in the model's colour order
//     interpolation: cubic # linear | cubic | area | nearest
//     color: rgb           # colour order fed to the network: rgb | bgr
//     units: unit          # unit: mean/std in 0..1 units (x = (p/255 - mean) / std)
//                          # byte: mean/std in 0..255 units (x = (p - mean) / std)
//     mean: [0.485, 0.456, 0.406]
//     std: [0.229, 0.224, 0.225]
//   output:
//     kind: metric         # metric: depth = scale * y
//                          # inverse: depth = scale / y
//                          # disparity: depth = baseline_focal / y (focal in pixels)
//                          # disparity_width: y is a disparity as a fraction of the image
//                          # width (PyDNet, Monodepth): depth = baseline * fx / (y * W), fx
//                          # and W the original image's, so one spec serves every camera
//     scale: 1.0
//     baseline_focal: 0.0
//     baseline: 0.0        # disparity_width: the stereo baseline trained on (m; KITTI 0.54)
//     canonical_focal: 0   # > 0: Metric3D canonical camera, depth *= f_input / canonical_focal
//                          # with f_input = fx scaled to the network input resolution
//     min_depth: 0.0       # depths outside [min_depth, max_depth] become 0 (invalid)
//     max_depth: 80.0
//
//   domain: indoor         # indoor | outdoor: which network settings family `run` picks
//                          # (configs/network_indoor.yaml or network_outdoor.yaml)
//   uncertainty:           # the model's depth error model, sigma_z = z * (relative +
//     relative: 0.5        # per_metre * z), used to weigh depth in optimisation (replaces
//     per_metre: 0.0       # the network config's depth.error_relative / error_per_metre)
//
// Output: 1x1xhxw, 1xhxw or hxw. When h x w differs from the input it is taken to cover the
// same field (half-resolution outputs); the padding is cropped away, then the map is resized
// bilinearly to the image.

#include <yaml-cpp/yaml.h>

#include <array>
#include <filesystem>
#include <string>

#include "ademono/core/depth_error.h"
#include "ademono/dnn/preprocess.h"

namespace ademono {

template <typename Options>
class OptionsTable;

struct DepthModelSpec {
  enum class Resize { kFixed, kLetterbox, kMultiple };
  enum class Kind { kMetric, kInverse, kDisparity, kDisparityWidth };

  std::string name = "default";
  Resize resize = Resize::kFixed;
  int width = 0;  // fixed / letterbox; 0 = take the model's fixed input size
  int height = 0;
  bool long_side = true;  // multiple: side_length applies to the long side (else short)
  int side_length = 0;    // multiple: 0 = keep the image size
  int multiple_of = 1;
  PadPlacement pad = PadPlacement::kCentre;
  bool pad_none = false;  // multiple: round to the multiple (stretch) instead of padding
  std::array<double, 3> pad_value{0, 0, 0};
  int interpolation = 1;  // cv::INTER_LINEAR
  bool rgb = true;
  // Stored in 0..255 units whatever the YAML used.
  std::array<double, 3> mean{0.485 * 255, 0.456 * 255, 0.406 * 255};
  std::array<double, 3> std{0.229 * 255, 0.224 * 255, 0.225 * 255};

  Kind kind = Kind::kMetric;
  double scale = 1.0;
  double baseline_focal = 0.0;
  double baseline = 0.0;  // disparity_width
  double canonical_focal = 0.0;
  double min_depth = 0.0;
  double max_depth = 1000.0;

  std::string domain;             // "indoor", "outdoor" or "" (unknown)
  DepthErrorModel uncertainty;    // disabled when the spec gives none

  // Throws std::invalid_argument naming the first bad field.
  void Check() const;
  // Reads the YAML (keys as above; missing keys keep the defaults). InputError naming the file
  // and the key for a bad value or an unknown key.
  static DepthModelSpec FromYaml(const YAML::Node& node, const std::filesystem::path& path);
  static DepthModelSpec Load(const std::filesystem::path& path);
  // Every key (mean/std written with `units: byte`): FromYaml(ToYaml()) == *this.
  YAML::Node ToYaml() const;
  static const OptionsTable<DepthModelSpec>& Table();  // core/options_table.h
  bool operator==(const DepthModelSpec&) const = default;

  // Network input size for an image of `image_size`, and the size the image is scaled to
  // inside it (the rest is padding).
  void InputGeometry(cv::Size image_size, cv::Size* input_size, cv::Size* content_size) const;
  // Output value -> metres (0 for invalid), before the valid-range check. `focal_scale`:
  // canonical-focal models' fx ratio; `focal_over_width`: fx / W of the image (disparity_width).
  double ToDepth(double y, double focal_scale, double focal_over_width = 0.0) const;
};

std::string ToString(DepthModelSpec::Kind kind);
std::string ToString(DepthModelSpec::Resize resize);

}  // namespace ademono
