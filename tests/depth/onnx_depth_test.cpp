// The ONNX depth provider on tiny models whose output is a known function of the input
// (tools/make_test_models.py): y = mean over channels of the normalised network input.
#include "ademono/depth/onnx_depth.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <limits>

#include "ademono/core/error.h"
#include "ademono/depth/depth_factory.h"

namespace ademono {
namespace {

namespace fs = std::filesystem;
const fs::path kModels = fs::path(ADEMONO_SOURCE_DIR) / "tests/data/models";

Camera MakeCamera(int width, int height, double f = 500.0) {
  return Camera::Pinhole(width, height, f, width / 2.0, height / 2.0);
}

cv::Mat Grey(int width, int height, int value) {
  return cv::Mat(height, width, CV_8UC3, cv::Scalar::all(value));
}

// Writes `text` as a spec YAML into a fresh temp file and returns its path.
// One temp folder per test process, removed at exit.
struct TempDir {
  fs::path path =
      fs::temp_directory_path() / ("ademono_onnx_depth_test_" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

fs::path WriteSpec(const std::string& name, const std::string& text) {
  static const TempDir dir;
  const fs::path path = dir.path / (name + ".yaml");
  std::ofstream(path) << text;
  return path;
}

// A spec for the fixed 64x48 test models; `extra_input` / `output` fill in the rest.
std::string FixedSpec(const std::string& extra_input, const std::string& output) {
  return "input:\n  resize: fixed\n  width: 64\n  height: 48\n  units: byte\n  mean: 0\n"
         "  std: 25.5\n" +
         extra_input + "output:\n" + output;
}

void ExpectAll(const cv::Mat& depth, float value, float tolerance = 1e-5f) {
  ASSERT_EQ(depth.type(), CV_32FC1);
  double lo, hi;
  cv::minMaxLoc(depth, &lo, &hi);
  EXPECT_NEAR(lo, value, tolerance);
  EXPECT_NEAR(hi, value, tolerance);
}

OnnxDepthProvider Load(const std::string& model, const std::optional<fs::path>& spec = {}) {
  return OnnxDepthProvider(kModels / model, spec, OrtSessionOptions{});
}

TEST(OnnxDepthTest, MetricOutputUsesSiblingSpec) {
  auto provider = Load("depth_metric.onnx");
  EXPECT_EQ(provider.Spec().name, "test_depth_metric");
  // 128x96 grey 51 -> stretched to 64x48 -> y = 51 / 25.5 = 2 m everywhere.
  ExpectAll(provider.DepthFromImage(Grey(128, 96, 51), MakeCamera(128, 96)), 2.0f);
}

TEST(OnnxDepthTest, MetricOutputFollowsTheImagePixelByPixel) {
  auto provider = Load("depth_metric.onnx");
  // At the network's own size nothing is resampled: depth(u, v) = (2u) / 25.5.
  cv::Mat image(48, 64, CV_8UC3);
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 64; ++u) image.at<cv::Vec3b>(v, u) = cv::Vec3b::all(2 * u);
  }
  const cv::Mat depth = provider.DepthFromImage(image, MakeCamera(64, 48));
  for (int v = 0; v < 48; v += 7) {
    for (int u = 1; u < 64; u += 5) EXPECT_NEAR(depth.at<float>(v, u), 2.0 * u / 25.5, 1e-5);
  }
  EXPECT_EQ(depth.at<float>(10, 0), 0.f);  // y = 0 -> depth 0 -> invalid
}

TEST(OnnxDepthTest, InverseDepthTimesScale) {
  auto provider = Load("depth_inverse.onnx");  // rank-3 output, depth = 2 / y
  ExpectAll(provider.DepthFromImage(Grey(64, 48, 51), MakeCamera(64, 48)), 1.0f);
  ExpectAll(provider.DepthFromImage(Grey(64, 48, 102), MakeCamera(64, 48)), 0.5f);
}

TEST(OnnxDepthTest, DisparityWithBaselineFocalAtHalfResolution) {
  auto provider = Load("depth_disparity.onnx");  // 24x32 output, depth = 10 / y
  const cv::Mat depth = provider.DepthFromImage(Grey(100, 70, 51), MakeCamera(100, 70));
  EXPECT_EQ(depth.size(), cv::Size(100, 70));
  ExpectAll(depth, 5.0f);
}

TEST(OnnxDepthTest, ColourOrderAndPerChannelNormalisation) {
  // Only the first network channel contributes: R for rgb, B for bgr.
  cv::Mat red(48, 64, CV_8UC3, cv::Scalar(0, 0, 153));
  const std::string output = "  kind: metric\n  scale: 1.0\n";
  for (const std::string colour : {"rgb", "bgr"}) {
    const auto spec =
        WriteSpec("colour_" + colour,
                  "input:\n  resize: fixed\n  width: 64\n  height: 48\n  color: " + colour +
                      "\n  units: byte\n  mean: [0, 0, 0]\n"
                      "  std: [25.5, 1.0e9, 1.0e9]\n"
                      "output:\n" +
                      output);
    auto provider = Load("depth_metric.onnx", spec);
    // rgb: y = (153 / 25.5) / 3 = 2; bgr: y ~ 0 -> tiny depth, below min_depth 0.01.
    const cv::Mat depth = provider.DepthFromImage(red, MakeCamera(64, 48));
    if (colour == "rgb") {
      ExpectAll(depth, 2.0f);
    } else {
      EXPECT_LT(cv::norm(depth, cv::NORM_INF), 1e-6);
    }
  }
}

TEST(OnnxDepthTest, UnitMeanStdMatchByteMeanStd) {
  // mean 0.2 / std 0.1 in 0..1 units == mean 51 / std 25.5 in 0..255 units: grey 102 -> y = 2.
  const auto unit = WriteSpec("unit",
                              "input:\n  units: unit\n  mean: 0.2\n  std: 0.1\n"
                              "output:\n  kind: metric\n");
  auto provider = Load("depth_metric.onnx", unit);
  EXPECT_EQ(provider.Spec().width, 64);  // taken from the model
  ExpectAll(provider.DepthFromImage(Grey(64, 48, 102), MakeCamera(64, 48)), 2.0f);
}

TEST(OnnxDepthTest, LetterboxPaddingIsRemoved) {
  // 64x64 into 64x48: content 48x48 centred, 8 px of black padding left and right, which would
  // read as y = 0 (invalid) if it leaked into the output.
  const auto spec = WriteSpec(
      "letterbox",
      FixedSpec("  resize: letterbox\n  pad: centre\n  pad_value: 0\n", "  kind: metric\n"));
  auto provider = Load("depth_metric.onnx", spec);
  ExpectAll(provider.DepthFromImage(Grey(64, 64, 51), MakeCamera(64, 64)), 2.0f);
}

TEST(OnnxDepthTest, DynamicSizeMultipleOfWithPadding) {
  auto provider = Load("depth_dynamic.onnx");
  cv::Size input, content;
  provider.Spec().InputGeometry({90, 40}, &input, &content);
  EXPECT_EQ(content, cv::Size(64, 28));
  EXPECT_EQ(input, cv::Size(64, 32));
  ExpectAll(provider.DepthFromImage(Grey(90, 40, 51), MakeCamera(90, 40)), 2.0f);
  // Same with centred padding and the short side scaled.
  const auto centre =
      WriteSpec("centre",
                "input:\n  resize: multiple\n  side: short\n  side_length: 40\n  multiple_of: 16\n"
                "  pad: centre\n  units: byte\n  mean: 0\n  std: 25.5\noutput:\n  kind: metric\n");
  auto centred = Load("depth_dynamic.onnx", centre);
  centred.Spec().InputGeometry({90, 30}, &input, &content);
  EXPECT_EQ(content, cv::Size(120, 40));
  EXPECT_EQ(input, cv::Size(128, 48));
  ExpectAll(centred.DepthFromImage(Grey(90, 30, 51), MakeCamera(90, 30)), 2.0f);
}

TEST(OnnxDepthTest, DynamicSizeRoundedToMultipleWithoutPadding) {
  // Depth Anything's resize: short side to 20, sides rounded to multiples of 14, no padding.
  const auto spec =
      WriteSpec("pad_none",
                "input:\n  resize: multiple\n  side: short\n  side_length: 20\n"
                "  multiple_of: 14\n  pad: none\n  interpolation: cubic\n  units: byte\n"
                "  mean: 0\n  std: 25.5\noutput:\n  kind: metric\n");
  auto provider = Load("depth_dynamic.onnx", spec);
  cv::Size input, content;
  provider.Spec().InputGeometry({64, 48}, &input, &content);
  EXPECT_EQ(input, cv::Size(28, 28));  // 26.7 x 20 -> 28 x 28 (20 rounds down to 14 < 20: ceil)
  ExpectAll(provider.DepthFromImage(Grey(64, 48, 51), MakeCamera(64, 48)), 2.0f);
}

TEST(OnnxDepthTest, DisparityAsAFractionOfTheImageWidth) {
  // y = grey / 25.5 = 2 for grey 51 (the half-resolution disparity model, resampled back).
  // depth = baseline * fx / (y * W): 0.54 * 500 / (2 * 128) = 1.0546875 m by hand, at whatever
  // size the network sees the image.
  const auto spec = WriteSpec(
      "disparity_width", FixedSpec("", "  kind: disparity_width\n  baseline: 0.54\n"));
  auto provider = Load("depth_disparity.onnx", spec);
  ExpectAll(provider.DepthFromImage(Grey(128, 96, 51), MakeCamera(128, 96, 500.0)), 1.0546875f);
  // A wider lens on the same sensor (fx 250): half the depth for the same disparity fraction.
  ExpectAll(provider.DepthFromImage(Grey(128, 96, 51), MakeCamera(128, 96, 250.0)), 0.52734375f);
  // A camera given at twice the image's resolution: fx / W unchanged, so the depth too.
  ExpectAll(provider.DepthFromImage(Grey(128, 96, 51), MakeCamera(256, 192, 1000.0)), 1.0546875f);
  // Grey 102: y = 4, half the depth.
  ExpectAll(provider.DepthFromImage(Grey(128, 96, 102), MakeCamera(128, 96, 500.0)), 0.52734375f);
  Camera unknown;  // no intrinsics: no way to convert
  EXPECT_THROW(provider.DepthFromImage(Grey(128, 96, 51), unknown), std::invalid_argument);
}

TEST(OnnxDepthTest, CanonicalFocalScalesByFocalAtNetworkResolution) {
  // 128x96 -> 64x48 halves fx = 500 to 250: depth = y * 250 / 1000 = 2 * 0.25.
  const auto spec =
      WriteSpec("canonical", FixedSpec("", "  kind: metric\n  canonical_focal: 1000\n"));
  auto provider = Load("depth_metric.onnx", spec);
  ExpectAll(provider.DepthFromImage(Grey(128, 96, 51), MakeCamera(128, 96, 500.0)), 0.5f);
}

TEST(OnnxDepthTest, ValidRangeMarksOutsideAsInvalid) {
  const auto spec =
      WriteSpec("range", FixedSpec("", "  kind: metric\n  min_depth: 0.5\n  max_depth: 1.5\n"));
  auto provider = Load("depth_metric.onnx", spec);
  ExpectAll(provider.DepthFromImage(Grey(64, 48, 51), MakeCamera(64, 48)), 0.0f);  // 2 m
  ExpectAll(provider.DepthFromImage(Grey(64, 48, 25), MakeCamera(64, 48)), 25 / 25.5f);
  ExpectAll(provider.DepthFromImage(Grey(64, 48, 10), MakeCamera(64, 48)), 0.0f);  // 0.39 m
}

TEST(OnnxDepthTest, DeterministicAcrossCalls) {
  auto provider = Load("depth_dynamic.onnx");
  cv::Mat image(37, 53, CV_8UC3);
  cv::randu(image, 0, 255);
  const cv::Mat a = provider.DepthFromImage(image, MakeCamera(53, 37));
  const cv::Mat b = provider.DepthFromImage(image, MakeCamera(53, 37));
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

std::string LoadError(const fs::path& model, const std::optional<fs::path>& spec = {}) {
  try {
    OnnxDepthProvider provider(model, spec, OrtSessionOptions{});
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(OnnxDepthTest, BadModelsFailAtLoadNamingTheFile) {
  EXPECT_THAT(LoadError(kModels / "missing.onnx"),
              testing::HasSubstr("missing.onnx: no such file"));
  // No sibling garbage.yaml: the model itself is what fails.
  const fs::path corrupt = WriteSpec("unused", "").parent_path() / "garbage.onnx";
  std::ofstream(corrupt) << "this is not a protobuf";
  const std::string corrupt_error = LoadError(corrupt);
  EXPECT_THAT(corrupt_error, testing::HasSubstr(corrupt.string() + ": cannot load ONNX model"));
  EXPECT_EQ(corrupt_error.find('\n'), std::string::npos);

  const std::string bad_output = LoadError(kModels / "depth_bad_output.onnx");
  EXPECT_THAT(bad_output, testing::HasSubstr("depth_bad_output.onnx"));
  EXPECT_THAT(bad_output, testing::HasSubstr("1x2x48x64"));

  // A spec size that differs from the model's fixed input.
  const auto small = WriteSpec("small", "input:\n  width: 32\n  height: 32\n");
  EXPECT_THAT(LoadError(kModels / "depth_metric.onnx", small),
              testing::AllOf(testing::HasSubstr("1x3x48x64"), testing::HasSubstr("32x32")));
  // resize: multiple needs a dynamic model; a dynamic model needs a size for fixed.
  const auto multiple = WriteSpec("multiple", "input:\n  resize: multiple\n  multiple_of: 8\n");
  EXPECT_THAT(LoadError(kModels / "depth_metric.onnx", multiple), testing::HasSubstr("fixed size"));
  const auto fixed = WriteSpec("fixed_no_size", "input:\n  resize: fixed\n");
  EXPECT_THAT(LoadError(kModels / "depth_dynamic.onnx", fixed), testing::HasSubstr("1x3x?x?"));
}

TEST(OnnxDepthTest, FactoryModelBranch) {
  DepthFactoryContext context;
  auto provider = MakeDepthProvider("model:" + (kModels / "depth_metric.onnx").string() +
                                        ",spec=" + (kModels / "depth_inverse.yaml").string(),
                                    context);
  EXPECT_THAT(provider->Name(), testing::HasSubstr("test_depth_inverse"));
  FrameData frame;
  frame.image = Grey(64, 48, 51);
  ExpectAll(provider->Depth(frame, MakeCamera(64, 48)), 1.0f);
  EXPECT_THROW(
      MakeDepthProvider("model:" + (kModels / "depth_metric.onnx").string() + ",bogus=1", context),
      InputError);
  EXPECT_THROW(MakeDepthProvider("model:", context), InputError);
}

TEST(DepthMapFilesTest, MillimetrePngAndInvalidValues) {
  cv::Mat depth(1, 4, CV_32F);
  depth.at<float>(0, 0) = 1.2345f;
  depth.at<float>(0, 1) = 0.f;
  depth.at<float>(0, 2) = 70.f;  // beyond uint16 mm
  depth.at<float>(0, 3) = std::numeric_limits<float>::quiet_NaN();
  const cv::Mat mm = DepthToMillimetres(depth);
  EXPECT_EQ(mm.at<uint16_t>(0, 0), 1235);
  EXPECT_EQ(mm.at<uint16_t>(0, 1), 0);
  EXPECT_EQ(mm.at<uint16_t>(0, 2), 0);
  EXPECT_EQ(mm.at<uint16_t>(0, 3), 0);
  EXPECT_THROW(WriteDepthMap(fs::temp_directory_path() / "depth.jpg", depth), InputError);
  const cv::Mat preview = ColouriseDepth(depth);
  EXPECT_EQ(preview.type(), CV_8UC3);
  EXPECT_EQ(preview.at<cv::Vec3b>(0, 1), cv::Vec3b(0, 0, 0));
}

}  // namespace
}  // namespace ademono
