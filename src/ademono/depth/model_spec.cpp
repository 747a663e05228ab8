#include "ademono/depth/model_spec.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "ademono/core/error.h"
#include "ademono/core/yaml_util.h"

namespace ademono {
namespace {

// input.mean, input.std, input.pad_value: one number for all channels or a list of 3.
std::array<double, 3> ReadTriple(const YAML::Node& node, const char* key,
                                 std::array<double, 3> value) {
  constexpr const char* kExpected = "a number or a list of 3 numbers";
  if (node && node.IsMap() && node[key] && node[key].IsScalar()) {
    value.fill(ReadYamlKey(node, "input", key, 0.0, kExpected));
    return value;
  }
  return ReadYamlKey(node, "input", key, value, kExpected);
}

// Spec sections are maps when present; unlike the SLAM config, an empty `input:` is an error.
void CheckSectionKeys(const YAML::Node& node, const char* section,
                      std::initializer_list<std::string_view> keys) {
  if (node && node.IsNull())
    throw std::invalid_argument(std::string("'") + section + "' is empty, expected a map");
  CheckYamlKeys(node, section, keys);
}

int RoundUp(int value, int multiple) { return (value + multiple - 1) / multiple * multiple; }

}  // namespace

std::string ToString(DepthModelSpec::Kind kind) {
  switch (kind) {
    case DepthModelSpec::Kind::kMetric:
      return "metric";
    case DepthModelSpec::Kind::kInverse:
      return "inverse";
    case DepthModelSpec::Kind::kDisparity:
      return "disparity";
  }
  return "?";
}

std::string ToString(DepthModelSpec::Resize resize) {
  switch (resize) {
    case DepthModelSpec::Resize::kFixed:
      return "fixed";
    case DepthModelSpec::Resize::kLetterbox:
      return "letterbox";
    case DepthModelSpec::Resize::kMultiple:
      return "multiple";
  }
  return "?";
}

void DepthModelSpec::Check() const {
  auto fail = [](const std::string& message) { throw std::invalid_argument(message); };
  if (resize != Resize::kMultiple) {
    if (width < 0 || height < 0 || (width == 0) != (height == 0)) {
      fail("input.width and input.height must both be positive (or both 0 = model size)");
    }
  } else {
    if (side_length < 0) fail("input.side_length must be >= 0");
  }
  if (multiple_of < 1) fail("input.multiple_of must be >= 1");
  if (pad_none && resize != Resize::kMultiple) fail("input.pad: none needs resize: multiple");
  for (int c = 0; c < 3; ++c) {
    if (!(std[c] > 0)) fail("input.std must be positive");
  }
  if (kind == Kind::kDisparity && !(baseline_focal > 0)) {
    fail("output.baseline_focal must be positive for kind disparity");
  }
  if (kind != Kind::kDisparity && !(scale > 0)) fail("output.scale must be positive");
  if (canonical_focal < 0) fail("output.canonical_focal must be >= 0");
  if (canonical_focal > 0 && kind != Kind::kMetric) {
    fail("output.canonical_focal applies to kind metric only");
  }
  if (!(min_depth >= 0 && max_depth > min_depth)) {
    fail("output.min_depth/max_depth must satisfy 0 <= min_depth < max_depth");
  }
}

DepthModelSpec DepthModelSpec::FromYaml(const YAML::Node& node, const std::filesystem::path& path) {
  DepthModelSpec spec;
  if (!node || !node.IsMap()) ThrowInputError(path, "model spec must be a YAML mapping");
  try {
    CheckYamlKeys(node, "spec", {"name", "input", "output", "domain", "uncertainty"});
    spec.name = ReadYamlKey(node, "spec", "name", spec.name);
    spec.domain = ReadYamlChoice<std::string>(
        node, "spec", "domain", {{"indoor", "indoor"}, {"outdoor", "outdoor"}}, "");
    const YAML::Node uncertainty = node["uncertainty"];
    CheckSectionKeys(uncertainty, "uncertainty", {"relative", "per_metre"});
    spec.uncertainty.relative = ReadYamlKey(uncertainty, "uncertainty", "relative", 0.0);
    spec.uncertainty.per_metre = ReadYamlKey(uncertainty, "uncertainty", "per_metre", 0.0);
    if (spec.uncertainty.relative < 0 || spec.uncertainty.per_metre < 0) {
      throw std::invalid_argument("uncertainty: relative and per_metre must be >= 0");
    }
    const YAML::Node in = node["input"];
    CheckSectionKeys(in, "input",
                     {"resize", "width", "height", "side", "side_length", "multiple_of", "pad",
                      "pad_value", "interpolation", "color", "units", "mean", "std"});
    spec.resize = ReadYamlChoice<Resize>(in, "input", "resize",
                                         {{"fixed", Resize::kFixed},
                                          {"letterbox", Resize::kLetterbox},
                                          {"multiple", Resize::kMultiple}},
                                         spec.resize);
    spec.width = ReadYamlKey(in, "input", "width", spec.width);
    spec.height = ReadYamlKey(in, "input", "height", spec.height);
    spec.long_side =
        ReadYamlChoice<bool>(in, "input", "side", {{"long", true}, {"short", false}}, true);
    spec.side_length = ReadYamlKey(in, "input", "side_length", spec.side_length);
    spec.multiple_of = ReadYamlKey(in, "input", "multiple_of", spec.multiple_of);
    spec.pad_none = ReadYamlKey(in, "input", "pad", std::string()) == "none";
    if (!spec.pad_none) {
      spec.pad = ReadYamlChoice<PadPlacement>(in, "input", "pad",
                                              {{"centre", PadPlacement::kCentre},
                                               {"center", PadPlacement::kCentre},
                                               {"bottom_right", PadPlacement::kTopLeft}},
                                              spec.pad);
    }
    spec.pad_value = ReadTriple(in, "pad_value", spec.pad_value);
    spec.interpolation = ReadYamlChoice<int>(in, "input", "interpolation",
                                             {{"linear", cv::INTER_LINEAR},
                                              {"cubic", cv::INTER_CUBIC},
                                              {"area", cv::INTER_AREA},
                                              {"nearest", cv::INTER_NEAREST}},
                                             spec.interpolation);
    spec.rgb = ReadYamlChoice<bool>(in, "input", "color", {{"rgb", true}, {"bgr", false}}, true);
    const bool unit = ReadYamlChoice<bool>(in, "input", "units", {{"unit", true}, {"byte", false}},
                                           /*default: mean/std in 0..1*/ true);
    const double factor = unit ? 255.0 : 1.0;
    std::array<double, 3> mean{0.485, 0.456, 0.406}, std{0.229, 0.224, 0.225};
    if (!unit) {
      for (int c = 0; c < 3; ++c) mean[c] *= 255, std[c] *= 255;
    }
    mean = ReadTriple(in, "mean", mean);
    std = ReadTriple(in, "std", std);
    for (int c = 0; c < 3; ++c) {
      spec.mean[c] = mean[c] * factor;
      spec.std[c] = std[c] * factor;
    }

    const YAML::Node out = node["output"];
    CheckSectionKeys(
        out, "output",
        {"kind", "scale", "baseline_focal", "canonical_focal", "min_depth", "max_depth"});
    spec.kind = ReadYamlChoice<Kind>(
        out, "output", "kind",
        {{"metric", Kind::kMetric}, {"inverse", Kind::kInverse}, {"disparity", Kind::kDisparity}},
        spec.kind);
    spec.scale = ReadYamlKey(out, "output", "scale", spec.scale);
    spec.baseline_focal = ReadYamlKey(out, "output", "baseline_focal", spec.baseline_focal);
    spec.canonical_focal = ReadYamlKey(out, "output", "canonical_focal", spec.canonical_focal);
    spec.min_depth = ReadYamlKey(out, "output", "min_depth", spec.min_depth);
    spec.max_depth = ReadYamlKey(out, "output", "max_depth", spec.max_depth);
    spec.Check();
  } catch (const std::invalid_argument& e) {
    ThrowInputError(path, e.what());
  }
  return spec;
}

DepthModelSpec DepthModelSpec::Load(const std::filesystem::path& path) {
  RequireFile(path);
  YAML::Node node;
  try {
    node = YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    ThrowInputError(path, "not valid YAML: " + e.msg);
  }
  return FromYaml(node, path);
}

void DepthModelSpec::InputGeometry(cv::Size image_size, cv::Size* input_size,
                                   cv::Size* content_size) const {
  switch (resize) {
    case Resize::kFixed:
      *input_size = {width, height};
      *content_size = *input_size;
      return;
    case Resize::kLetterbox:
      *input_size = {width, height};
      *content_size = FitInside(image_size, *input_size, /*round_content=*/true);
      return;
    case Resize::kMultiple: {
      double s = 1.0;
      if (side_length > 0) {
        const int side = long_side ? std::max(image_size.width, image_size.height)
                                   : std::min(image_size.width, image_size.height);
        s = static_cast<double>(side_length) / side;
      }
      if (pad_none) {
        // Nearest multiple, but not below side_length when that bounds the short side.
        const int min_side = long_side ? multiple_of : std::max(multiple_of, side_length);
        auto constrain = [&](double x) {
          int y = static_cast<int>(std::lround(x / multiple_of)) * multiple_of;
          if (y < min_side) y = static_cast<int>(std::ceil(x / multiple_of)) * multiple_of;
          return std::max(y, multiple_of);
        };
        *input_size = {constrain(image_size.width * s), constrain(image_size.height * s)};
        *content_size = *input_size;
        return;
      }
      *content_size = {std::max(1, static_cast<int>(std::lround(image_size.width * s))),
                       std::max(1, static_cast<int>(std::lround(image_size.height * s)))};
      *input_size = {RoundUp(content_size->width, multiple_of),
                     RoundUp(content_size->height, multiple_of)};
      return;
    }
  }
}

double DepthModelSpec::ToDepth(double y, double focal_scale) const {
  switch (kind) {
    case Kind::kMetric:
      return scale * y * focal_scale;
    case Kind::kInverse:
      return y > 0 ? scale / y : 0.0;
    case Kind::kDisparity:
      return y > 0 ? baseline_focal / y : 0.0;
  }
  return 0.0;
}

}  // namespace ademono
