#include "ademono/depth/model_spec.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <opencv2/imgproc.hpp>

#include "ademono/core/error.h"

namespace ademono {
namespace {

namespace fs = std::filesystem;

DepthModelSpec Parse(const std::string& text) {
  return DepthModelSpec::FromYaml(YAML::Load(text), "spec.yaml");
}

std::string ParseError(const std::string& text) {
  try {
    Parse(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ModelSpecTest, DefaultsAreImageNetMetric) {
  const DepthModelSpec spec = Parse("name: x\n");
  EXPECT_EQ(spec.resize, DepthModelSpec::Resize::kFixed);
  EXPECT_TRUE(spec.rgb);
  EXPECT_NEAR(spec.mean[0], 0.485 * 255, 1e-9);
  EXPECT_NEAR(spec.std[2], 0.225 * 255, 1e-9);
  EXPECT_EQ(spec.kind, DepthModelSpec::Kind::kMetric);
  EXPECT_EQ(spec.ToDepth(2.5, 1.0), 2.5);
}

TEST(ModelSpecTest, ParsesEveryField) {
  const DepthModelSpec spec = Parse(R"(
name: full
input:
  resize: multiple
  side: short
  side_length: 384
  multiple_of: 32
  pad: bottom_right
  pad_value: [1, 2, 3]
  interpolation: cubic
  color: bgr
  units: byte
  mean: [10, 20, 30]
  std: 2
output:
  kind: inverse
  scale: 3.0
  min_depth: 0.2
  max_depth: 9
)");
  EXPECT_EQ(spec.name, "full");
  EXPECT_EQ(spec.resize, DepthModelSpec::Resize::kMultiple);
  EXPECT_FALSE(spec.long_side);
  EXPECT_EQ(spec.side_length, 384);
  EXPECT_EQ(spec.multiple_of, 32);
  EXPECT_EQ(spec.pad, PadPlacement::kTopLeft);
  EXPECT_EQ(spec.pad_value[2], 3.0);
  EXPECT_EQ(spec.interpolation, cv::INTER_CUBIC);
  EXPECT_FALSE(spec.rgb);
  EXPECT_EQ(spec.mean[1], 20.0);
  EXPECT_EQ(spec.std[0], 2.0);
  EXPECT_EQ(spec.kind, DepthModelSpec::Kind::kInverse);
  EXPECT_DOUBLE_EQ(spec.ToDepth(2.0, 1.0), 1.5);
  EXPECT_EQ(spec.ToDepth(0.0, 1.0), 0.0);
  EXPECT_EQ(spec.min_depth, 0.2);
  cv::Size input, content;
  spec.InputGeometry({640, 480}, &input, &content);
  EXPECT_EQ(content, cv::Size(512, 384));
  EXPECT_EQ(input, cv::Size(512, 384));
}

TEST(ModelSpecTest, UnitMeanStdAreConvertedTo0To255) {
  const DepthModelSpec spec = Parse("input:\n  units: unit\n  mean: [0.5, 0.5, 0.5]\n  std: 0.5\n");
  EXPECT_DOUBLE_EQ(spec.mean[0], 127.5);
  EXPECT_DOUBLE_EQ(spec.std[1], 127.5);
}

TEST(ModelSpecTest, DisparityAndCanonicalFocal) {
  const DepthModelSpec disparity = Parse("output:\n  kind: disparity\n  baseline_focal: 40\n");
  EXPECT_DOUBLE_EQ(disparity.ToDepth(8.0, 1.0), 5.0);
  const DepthModelSpec canonical = Parse("output:\n  kind: metric\n  canonical_focal: 1000\n");
  EXPECT_DOUBLE_EQ(canonical.ToDepth(4.0, 0.5), 2.0);
}

TEST(ModelSpecTest, DisparityAsAFractionOfTheWidth) {
  // PyDNet on KITTI: depth = 0.54 m * fx / (d * W). By hand, fx = 718.856, W = 1241, d = 0.1:
  // 0.54 * 718.856 = 388.18224; 0.1 * 1241 = 124.1; 388.18224 / 124.1 = 3.12798...
  const DepthModelSpec spec = Parse("output:\n  kind: disparity_width\n  baseline: 0.54\n");
  EXPECT_EQ(spec.kind, DepthModelSpec::Kind::kDisparityWidth);
  EXPECT_NEAR(spec.ToDepth(0.1, 1.0, 718.856 / 1241.0), 3.1279793714746172, 1e-12);
  // d = 0.02 (a far point): five times as far.
  EXPECT_NEAR(spec.ToDepth(0.02, 1.0, 718.856 / 1241.0), 15.639896857373086, 1e-12);
  // The same camera at half resolution (fx and W both halved) reads the same depth.
  EXPECT_DOUBLE_EQ(spec.ToDepth(0.1, 1.0, 359.428 / 620.5),
                   spec.ToDepth(0.1, 1.0, 718.856 / 1241.0));
  EXPECT_EQ(spec.ToDepth(0.0, 1.0, 0.5), 0.0);
  EXPECT_EQ(spec.ToDepth(-0.1, 1.0, 0.5), 0.0);
  EXPECT_EQ(spec.ToDepth(0.1, 1.0, 0.0), 0.0);  // no camera: no depth
  EXPECT_EQ(ToString(spec.kind), "disparity_width");
  EXPECT_THAT(ParseError("output:\n  kind: disparity_width\n"), testing::HasSubstr("baseline"));
  EXPECT_THAT(ParseError("output:\n  kind: disparity_width\n  baseline: -0.5\n"),
              testing::HasSubstr("output.baseline"));
  // Round trip through ToYaml.
  EXPECT_TRUE(DepthModelSpec::FromYaml(spec.ToYaml(), "back.yaml") == spec);
  EXPECT_EQ(spec.ToYaml()["output"]["kind"].as<std::string>(), "disparity_width");
  EXPECT_EQ(spec.ToYaml()["output"]["baseline"].as<double>(), 0.54);
}

TEST(ModelSpecTest, LetterboxGeometry) {
  const DepthModelSpec spec = Parse("input:\n  resize: letterbox\n  width: 1064\n  height: 616\n");
  cv::Size input, content;
  spec.InputGeometry({640, 480}, &input, &content);
  EXPECT_EQ(input, cv::Size(1064, 616));
  EXPECT_EQ(content, cv::Size(821, 616));
}

TEST(ModelSpecTest, ErrorsNameTheFileAndKey) {
  EXPECT_EQ(ParseError("input:\n  colour: rgb\n"), "spec.yaml: unknown key 'input.colour'");
  EXPECT_EQ(ParseError("output:\n  kind: depthish\n"),
            "spec.yaml: output.kind: cannot parse 'depthish', expected one of metric, inverse, "
            "disparity, disparity_width");
  EXPECT_EQ(ParseError("input:\n  width: wide\n"), "spec.yaml: input.width: cannot parse 'wide'");
  EXPECT_EQ(ParseError("input:\n  mean: [1, 2]\n"),
            "spec.yaml: input.mean: cannot parse '[1, 2]', expected a number or a list of 3 "
            "numbers");
  EXPECT_EQ(ParseError("input:\n  std: x\n"),
            "spec.yaml: input.std: cannot parse 'x', expected a number or a list of 3 numbers");
  EXPECT_EQ(ParseError("input:\n"), "spec.yaml: 'input' is empty, expected a map");
  EXPECT_EQ(ParseError("output: [1]\n"), "spec.yaml: 'output' must be a map");
  EXPECT_EQ(ParseError("input:\n  pad: left\n"),
            "spec.yaml: input.pad: cannot parse 'left', expected one of centre, center, "
            "bottom_right");
  EXPECT_THAT(ParseError("input:\n  std: 0\n"), testing::HasSubstr("std"));
  EXPECT_THAT(ParseError("output:\n  kind: disparity\n"), testing::HasSubstr("baseline_focal"));
  EXPECT_THAT(ParseError("output:\n  min_depth: 5\n  max_depth: 1\n"),
              testing::HasSubstr("min_depth"));
  EXPECT_THAT(ParseError("input:\n  width: 10\n"), testing::HasSubstr("height"));
  EXPECT_THAT(ParseError("output:\n  kind: inverse\n  canonical_focal: 100\n"),
              testing::HasSubstr("canonical_focal"));
  EXPECT_THAT(ParseError("- 1\n- 2\n"), testing::HasSubstr("mapping"));
  EXPECT_THROW(DepthModelSpec::Load("/no/such/spec.yaml"), InputError);
}

TEST(ModelSpecTest, PadNoneRoundsToTheMultipleLikeDepthAnything) {
  const DepthModelSpec spec = Parse(
      "input:\n  resize: multiple\n  side: short\n  side_length: 518\n  multiple_of: 14\n"
      "  pad: none\n");
  cv::Size input, content;
  // 640x480 -> x 518/480 -> 690.7 x 518 -> nearest multiples of 14: 686 x 518.
  spec.InputGeometry({640, 480}, &input, &content);
  EXPECT_EQ(input, cv::Size(686, 518));
  EXPECT_EQ(content, input);
  // Portrait 480x640 -> 518 x 690.7.
  spec.InputGeometry({480, 640}, &input, &content);
  EXPECT_EQ(input, cv::Size(518, 686));
  EXPECT_THAT(ParseError("input:\n  resize: fixed\n  pad: none\n"), testing::HasSubstr("pad"));
}

TEST(ModelSpecTest, ShippedSpecsLoad) {
  const fs::path dir = fs::path(ADEMONO_SOURCE_DIR) / "configs/models";
  int count = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(DepthModelSpec::Load(entry.path()));
    ++count;
  }
  EXPECT_GE(count, 4);
}

// Every shipped and test spec reads back to the same values from its ToYaml (mean/std written
// in byte units, `pad: none` and the `center` spelling included).
TEST(ModelSpecTest, ToYamlRoundTripsEveryShippedSpec) {
  int count = 0;
  for (const fs::path& dir : {fs::path(ADEMONO_SOURCE_DIR) / "configs" / "models",
                              fs::path(ADEMONO_SOURCE_DIR) / "tests" / "data" / "models"}) {
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.path().extension() != ".yaml") continue;
      SCOPED_TRACE(entry.path().string());
      const DepthModelSpec spec = DepthModelSpec::Load(entry.path());
      const DepthModelSpec back = DepthModelSpec::FromYaml(spec.ToYaml(), "back.yaml");
      EXPECT_TRUE(back == spec);
      ++count;
    }
  }
  EXPECT_GE(count, 9);
  DepthModelSpec spec = Parse(
      "input:\n  resize: multiple\n  pad: none\n  units: unit\n  mean: 0.5\n"
      "output:\n  kind: inverse\n  scale: 0.1\n");
  EXPECT_DOUBLE_EQ(spec.mean[1], 0.5 * 255);
  EXPECT_TRUE(DepthModelSpec::FromYaml(spec.ToYaml(), "back.yaml") == spec);
  spec.std[2] = 0.1 + 0.2;
  const DepthModelSpec changed = DepthModelSpec::FromYaml(spec.ToYaml(), "back.yaml");
  EXPECT_EQ(changed.std[2], 0.1 + 0.2);
  EXPECT_TRUE(changed.pad_none);
  EXPECT_EQ(changed.kind, DepthModelSpec::Kind::kInverse);
}

}  // namespace
}  // namespace ademono
