#include "ademono/depth/model_spec.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "ademono/core/error.h"
#include "ademono/core/options_table.h"

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

// input.units: mean/std in 0..1 (unit, the default) or 0..255 (byte) units.
bool UnitMeanStd(const YAML::Node& input) {
  return ReadYamlChoice<bool>(input, "input", "units", {{"unit", true}, {"byte", false}}, true);
}

using Triple = std::array<double, 3> DepthModelSpec::*;

OptionsTable<DepthModelSpec>::WriteFn WriteTriple(Triple member) {
  return [member](const DepthModelSpec& s) { return options_internal::Encode(s.*member); };
}

// input.mean / input.std, stored in 0..255 units whatever `units` says.
OptionsTable<DepthModelSpec>::ReadFn ReadMeanStd(const char* key, Triple member) {
  return [key, member](const YAML::Node&, const YAML::Node& in, DepthModelSpec& s) {
    const double factor = UnitMeanStd(in) ? 255.0 : 1.0;
    s.*member = ReadTriple(in, key, s.*member);
    for (double& v : s.*member) v *= factor;
  };
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
    case DepthModelSpec::Kind::kDisparityWidth:
      return "disparity_width";
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
  Table().CheckRanges(*this);
  if (!domain.empty() && domain != "indoor" && domain != "outdoor") {
    fail("domain must be indoor or outdoor, got '" + domain + "'");
  }
  if (resize != Resize::kMultiple) {
    if (width < 0 || height < 0 || (width == 0) != (height == 0)) {
      fail("input.width and input.height must both be positive (or both 0 = model size)");
    }
  } else {
    if (side_length < 0) fail("input.side_length must be >= 0");
  }
  if (pad_none && resize != Resize::kMultiple) fail("input.pad: none needs resize: multiple");
  for (int c = 0; c < 3; ++c) {
    if (!(std[c] > 0)) fail("input.std must be positive");
  }
  if (kind == Kind::kDisparity && !(baseline_focal > 0)) {
    fail("output.baseline_focal must be positive for kind disparity");
  }
  if (kind == Kind::kDisparityWidth && !(baseline > 0)) {
    fail("output.baseline must be positive for kind disparity_width");
  }
  if (kind != Kind::kDisparity && kind != Kind::kDisparityWidth && !(scale > 0))
    fail("output.scale must be positive");
  if (canonical_focal > 0 && kind != Kind::kMetric) {
    fail("output.canonical_focal applies to kind metric only");
  }
  if (!(min_depth >= 0 && max_depth > min_depth)) {
    fail("output.min_depth/max_depth must satisfy 0 <= min_depth < max_depth");
  }
}

const OptionsTable<DepthModelSpec>& DepthModelSpec::Table() {
  using S = DepthModelSpec;
  // Spec sections are maps when present; unlike the SLAM config, an empty `input:` is an error.
  static const auto input =
      OptionsTable<S>("input")
          .RejectEmpty()
          .AddChoice<Resize>("resize", &S::resize,
                             {{"fixed", Resize::kFixed},
                              {"letterbox", Resize::kLetterbox},
                              {"multiple", Resize::kMultiple}})
          .Add("width", &S::width)
          .Add("height", &S::height)
          .AddChoice<bool>("side", &S::long_side, {{"long", true}, {"short", false}})
          .Add("side_length", &S::side_length)
          .Add("multiple_of", &S::multiple_of, Range::AtLeast(1))
          .AddCustom(
              "pad",
              [](const YAML::Node&, const YAML::Node& in, S& s) {
                s.pad_none = ReadYamlKey(in, "input", "pad", std::string()) == "none";
                if (!s.pad_none) {
                  s.pad = ReadYamlChoice<PadPlacement>(in, "input", "pad",
                                                       {{"centre", PadPlacement::kCentre},
                                                        {"center", PadPlacement::kCentre},
                                                        {"bottom_right", PadPlacement::kTopLeft}},
                                                       s.pad);
                }
              },
              [](const S& s) {
                return YAML::Node(s.pad_none                       ? "none"
                                  : s.pad == PadPlacement::kCentre ? "centre"
                                                                   : "bottom_right");
              })
          .AddCustom(
              "pad_value",
              [](const YAML::Node&, const YAML::Node& in, S& s) {
                s.pad_value = ReadTriple(in, "pad_value", s.pad_value);
              },
              WriteTriple(&S::pad_value))
          .AddChoice<int>("interpolation", &S::interpolation,
                          {{"linear", cv::INTER_LINEAR},
                           {"cubic", cv::INTER_CUBIC},
                           {"area", cv::INTER_AREA},
                           {"nearest", cv::INTER_NEAREST}})
          .AddChoice<bool>("color", &S::rgb, {{"rgb", true}, {"bgr", false}})
          // Stored in 0..255 units: `units` only says how mean/std are written.
          .AddCustom(
              "units", [](const YAML::Node&, const YAML::Node& in, S&) { UnitMeanStd(in); },
              [](const S&) { return YAML::Node("byte"); })
          .AddCustom("mean", ReadMeanStd("mean", &S::mean), WriteTriple(&S::mean))
          .AddCustom("std", ReadMeanStd("std", &S::std), WriteTriple(&S::std));
  static const auto output = OptionsTable<S>("output")
                                 .RejectEmpty()
                                 .AddChoice<Kind>("kind", &S::kind,
                                                  {{"metric", Kind::kMetric},
                                                   {"inverse", Kind::kInverse},
                                                   {"disparity", Kind::kDisparity},
                                                   {"disparity_width", Kind::kDisparityWidth}})
                                 .Add("scale", &S::scale)
                                 .Add("baseline_focal", &S::baseline_focal)
                                 .Add("baseline", &S::baseline)
                                 .Add("canonical_focal", &S::canonical_focal, Range::AtLeast(0))
                                 .Add("min_depth", &S::min_depth)
                                 .Add("max_depth", &S::max_depth);
  static const auto uncertainty =
      OptionsTable<DepthErrorModel>("uncertainty")
          .Add("relative", &DepthErrorModel::relative, Range::AtLeast(0))
          .Add("per_metre", &DepthErrorModel::per_metre, Range::AtLeast(0));
  static const auto table = OptionsTable<S>("spec")
                                .Add("name", &S::name)
                                .Add("domain", &S::domain)
                                .AddSection("uncertainty", &S::uncertainty, uncertainty)
                                .AddSection("input", input)
                                .AddSection("output", output);
  return table;
}

DepthModelSpec DepthModelSpec::FromYaml(const YAML::Node& node, const std::filesystem::path& path) {
  DepthModelSpec spec;
  if (!node || !node.IsMap()) ThrowInputError(path, "model spec must be a YAML mapping");
  try {
    Table().Read(node, spec);
    spec.Check();
  } catch (const std::invalid_argument& e) {
    ThrowInputError(path, e.what());
  }
  return spec;
}

YAML::Node DepthModelSpec::ToYaml() const { return Table().Write(*this); }

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

double DepthModelSpec::ToDepth(double y, double focal_scale, double focal_over_width) const {
  switch (kind) {
    case Kind::kMetric:
      return scale * y * focal_scale;
    case Kind::kInverse:
      return y > 0 ? scale / y : 0.0;
    case Kind::kDisparity:
      return y > 0 ? baseline_focal / y : 0.0;
    case Kind::kDisparityWidth:
      return y > 0 && focal_over_width > 0 ? baseline * focal_over_width / y : 0.0;
  }
  return 0.0;
}

}  // namespace ademono
