// YOLO decoders, NMS and the detector on tiny constant-output heads (tools/make_test_models.py):
// exact expected boxes through letterbox, decoding, NMS, class filter and clipping.
#include "ademono/detect/yolo_detector.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "ademono/core/error.h"

namespace ademono {
namespace {

namespace fs = std::filesystem;
const fs::path kModels = fs::path(ADEMONO_SOURCE_DIR) / "tests/data/models";

void ExpectBox(const Detection& d, int class_id, float score, cv::Rect2f box) {
  EXPECT_EQ(d.class_id, class_id);
  EXPECT_NEAR(d.score, score, 1e-5);
  EXPECT_NEAR(d.box.x, box.x, 1e-3);
  EXPECT_NEAR(d.box.y, box.y, 1e-3);
  EXPECT_NEAR(d.box.width, box.width, 1e-3);
  EXPECT_NEAR(d.box.height, box.height, 1e-3);
}

DetectorOptions AllClasses(float score = 0.3f) {
  DetectorOptions options;
  options.class_ids.clear();
  options.score_threshold = score;
  return options;
}

// The heads' rows in network-input pixels (64x64): see DET_BOXES in make_test_models.py.
// A 128x64 image is scaled by 0.5 to 64x32 and centred: 16 px of padding on top.
class ConstantHeadTest : public testing::TestWithParam<std::pair<std::string, YoloArch>> {};

TEST_P(ConstantHeadTest, DecodesLetterboxedBoxesWithClassAwareNms) {
  const auto& [file, arch] = GetParam();
  const cv::Mat image(64, 128, CV_8UC3, cv::Scalar::all(90));
  YoloDetector detector(kModels / file, arch, AllClasses());
  EXPECT_EQ(detector.InputSize(), cv::Size(64, 64));
  const auto detections = detector.DetectImage(image);
  ASSERT_EQ(detections.size(), 2u);
  // Row 0: centre (32, 32), 20x10 -> input (22, 27)-(42, 37) -> image (44, 22) 40x20.
  ExpectBox(detections[0], 1, 0.9f * 0.8f, {44, 22, 40, 20});
  EXPECT_EQ(detections[0].class_name, "bicycle");
  // Row 2 (another class, overlapping row 0): centre (34, 33), 18x12 -> image (50, 22) 36x24.
  ExpectBox(detections[1], 2, 0.6f * 0.9f, {50, 22, 36, 24});
}

TEST_P(ConstantHeadTest, ClassAgnosticNmsSuppressesAcrossClasses) {
  const auto& [file, arch] = GetParam();
  DetectorOptions options = AllClasses();
  options.class_agnostic_nms = true;
  YoloDetector detector(kModels / file, arch, options);
  const auto detections = detector.DetectImage(cv::Mat(64, 128, CV_8UC3, cv::Scalar::all(0)));
  ASSERT_EQ(detections.size(), 1u);
  EXPECT_EQ(detections[0].class_id, 1);
}

TEST_P(ConstantHeadTest, LowThresholdKeepsTheWeakBoxClippedToTheImage) {
  const auto& [file, arch] = GetParam();
  YoloDetector detector(kModels / file, arch, AllClasses(0.2f));
  const auto detections = detector.DetectImage(cv::Mat(64, 128, CV_8UC3, cv::Scalar::all(0)));
  ASSERT_EQ(detections.size(), 3u);
  // Row 3: centre (10, 50), 8x8 -> input (6, 46)-(14, 54) -> image (12, 60)-(28, 76), clipped at
  // the image's bottom edge (64).
  ExpectBox(detections[2], 0, 0.25f, {12, 60, 16, 4});
}

TEST_P(ConstantHeadTest, ClassFilter) {
  const auto& [file, arch] = GetParam();
  DetectorOptions options = AllClasses();
  options.class_ids = {2, 5};
  YoloDetector detector(kModels / file, arch, options);
  const auto detections = detector.DetectImage(cv::Mat(64, 128, CV_8UC3, cv::Scalar::all(0)));
  ASSERT_EQ(detections.size(), 1u);
  EXPECT_EQ(detections[0].class_name, "car");
}

INSTANTIATE_TEST_SUITE_P(Heads, ConstantHeadTest,
                         testing::Values(std::make_pair("det_yolov5.onnx", YoloArch::kYolov5),
                                         std::make_pair("det_yolov8.onnx", YoloArch::kYolov8)));

TEST(YoloDetectorTest, Yolov5And8InputIsRgbOver255WithCentredGreyPadding) {
  // The probe's class-0 score is the mean of network channel 0. A pure red 64x32 image fills the
  // centre half of the 64x64 input; the rest is padding 114. With RGB / 255:
  // 0.5 * 255/255 + 0.5 * 114/255. (BGR order would give 0.5 * 114/255 only.)
  YoloDetector detector(kModels / "det_yolov8_probe.onnx", YoloArch::kYolov8, AllClasses());
  const cv::Mat red(32, 64, CV_8UC3, cv::Scalar(0, 0, 255));
  const auto detections = detector.DetectImage(red);
  ASSERT_EQ(detections.size(), 1u);
  EXPECT_NEAR(detections[0].score, 0.5f + 0.5f * 114.f / 255.f, 1e-5);
  // Box (32, 32, 10, 10) in the input -> (27, 27)-(37, 37) -> minus 16 rows of top padding.
  ExpectBox(detections[0], 0, detections[0].score, {27, 11, 10, 10});
  const cv::Mat blue(32, 64, CV_8UC3, cv::Scalar(255, 0, 0));
  ASSERT_EQ(detector.DetectImage(blue).size(), 0u);  // 0.22 < 0.3
}

TEST(YoloDecodeTest, YoloxGridStrideAndExpSizes) {
  // 64x64 input: 8x8 + 4x4 + 2x2 = 84 anchors, 2 classes.
  Tensor output;
  output.shape = {1, 84, 7};
  output.data.assign(84 * 7, 0.f);
  // Stride 16, cell (gx 1, gy 2): row 64 + 2 * 4 + 1.
  float* row = output.data.data() + (64 + 2 * 4 + 1) * 7;
  row[0] = 0.5f, row[1] = 0.25f, row[2] = std::log(2.f), row[3] = 0.f;
  row[4] = 0.9f, row[5] = 0.2f, row[6] = 0.5f;
  const auto candidates = DecodeYolox(output, {64, 64}, 0.3f);
  ASSERT_EQ(candidates.size(), 1u);
  // Centre ((0.5 + 1) * 16, (0.25 + 2) * 16) = (24, 36); size (2 * 16, 1 * 16).
  ExpectBox(candidates[0], 1, 0.45f, {8, 28, 32, 16});
  EXPECT_THROW(DecodeYolox(output, {96, 64}, 0.3f), std::invalid_argument);
}

TEST(YoloDecodeTest, Yolov5AndYolov8Layouts) {
  Tensor v5;
  v5.shape = {1, 2, 7};
  v5.data = {10, 20, 4,  6,  0.5f, 0.9f, 0.1f,  //
             30, 30, 10, 10, 0.2f, 0.1f, 0.9f};
  auto c5 = DecodeYolov5(v5, 0.3f);
  ASSERT_EQ(c5.size(), 1u);
  ExpectBox(c5[0], 0, 0.45f, {8, 17, 4, 6});
  Tensor v8;
  v8.shape = {1, 6, 2};  // channels x anchors
  v8.data = {10, 30, 20, 30, 4, 10, 6, 10, 0.1f, 0.2f, 0.35f, 0.1f};
  auto c8 = DecodeYolov8(v8, 0.3f);
  ASSERT_EQ(c8.size(), 1u);
  ExpectBox(c8[0], 1, 0.35f, {8, 17, 4, 6});
  Tensor wrong;
  wrong.shape = {2, 3};
  Tensor short_data;
  short_data.shape = {1, 2, 7};
  short_data.data.assign(7, 0.f);
  EXPECT_THROW(DecodeYolov5(short_data, 0.3f), std::invalid_argument);
  EXPECT_THROW(DecodeYolov5(wrong, 0.3f), std::invalid_argument);
  EXPECT_THROW(DecodeYolov8(wrong, 0.3f), std::invalid_argument);
}

TEST(YoloDecodeTest, NmsIsPerClassAndGreedyByScore) {
  auto make = [](int cls, float score, float x) {
    Detection d;
    d.class_id = cls;
    d.score = score;
    d.box = {x, 0, 10, 10};
    return d;
  };
  // IoU(0, 1) = 9/11 = 0.82; IoU(0, 5) = 5/15 = 0.33.
  const std::vector<Detection> candidates{make(0, 0.5f, 1), make(0, 0.9f, 0), make(1, 0.6f, 0),
                                          make(0, 0.4f, 5)};
  const auto kept = Nms(candidates, 0.45f);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_FLOAT_EQ(kept[0].score, 0.9f);
  EXPECT_FLOAT_EQ(kept[1].score, 0.6f);
  EXPECT_FLOAT_EQ(kept[2].score, 0.4f);
  EXPECT_EQ(Nms(candidates, 0.45f, /*class_agnostic=*/true).size(), 2u);
  EXPECT_EQ(Nms(candidates, 0.3f).size(), 2u);
}

TEST(YoloArchTest, ParseAndGuess) {
  EXPECT_EQ(ParseYoloArch("yolox"), YoloArch::kYolox);
  EXPECT_EQ(ParseYoloArch("yolov5"), YoloArch::kYolov5);
  EXPECT_EQ(ParseYoloArch("yolov8"), YoloArch::kYolov8);
  EXPECT_THROW(ParseYoloArch("yolov7"), std::invalid_argument);
  EXPECT_EQ(GuessYoloArch({1, 3549, 85}, {416, 416}), YoloArch::kYolox);
  EXPECT_EQ(GuessYoloArch({1, 8400, 85}, {640, 640}), YoloArch::kYolox);
  EXPECT_EQ(GuessYoloArch({1, 25200, 85}, {640, 640}), YoloArch::kYolov5);
  EXPECT_EQ(GuessYoloArch({1, 84, 8400}, {640, 640}), YoloArch::kYolov8);
  EXPECT_EQ(GuessYoloArch({1, 4, 13}, {64, 64}), YoloArch::kAuto);
}

std::string LoadError(const fs::path& model, YoloArch arch = YoloArch::kAuto) {
  try {
    YoloDetector detector(model, arch, AllClasses());
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(YoloDetectorTest, BadModelsFailAtLoadNamingTheFileAndShapes) {
  EXPECT_THAT(LoadError(kModels / "nope.onnx"), testing::HasSubstr("nope.onnx: no such file"));
  EXPECT_THAT(LoadError(kModels / "det_yolov5.onnx"),
              testing::AllOf(testing::HasSubstr("det_yolov5.onnx"), testing::HasSubstr("1x4x13"),
                             testing::HasSubstr("arch=")));
  EXPECT_THAT(LoadError(kModels / "depth_metric.onnx", YoloArch::kYolov5),
              testing::HasSubstr("1x1x48x64"));
  EXPECT_THAT(LoadError(kModels / "det_yolov5.onnx", YoloArch::kYolox),
              testing::HasSubstr("grid cells"));
  EXPECT_THAT(LoadError(kModels / "depth_metric.yaml", YoloArch::kYolox),
              testing::HasSubstr("cannot load ONNX model"));
}

}  // namespace
}  // namespace ademono
