#include "ademono/dnn/preprocess.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "ademono/core/error.h"
#include "ademono/dnn/model_arg.h"
#include "ademono/dnn/ort_session.h"

namespace ademono {
namespace {

namespace fs = std::filesystem;
const fs::path kModels = fs::path(ADEMONO_SOURCE_DIR) / "tests/data/models";

TEST(PreprocessTest, FitInsideTruncatesOrRounds) {
  EXPECT_EQ(FitInside({810, 1080}, {416, 416}, false), cv::Size(312, 416));
  EXPECT_EQ(FitInside({1441, 731}, {416, 416}, false), cv::Size(416, 211));
  EXPECT_EQ(FitInside({1441, 731}, {416, 416}, true), cv::Size(416, 211));
  EXPECT_EQ(FitInside({100, 33}, {64, 64}, false), cv::Size(64, 21));
  EXPECT_EQ(FitInside({100, 33}, {64, 64}, true), cv::Size(64, 21));
  EXPECT_EQ(FitInside({3, 2}, {64, 64}, true), cv::Size(64, 43));
  EXPECT_EQ(FitInside({3, 2}, {64, 64}, false), cv::Size(64, 42));
}

TEST(PreprocessTest, TopLeftAndCentredPadding) {
  const cv::Mat image(20, 40, CV_8UC3, cv::Scalar(1, 2, 3));
  ResizeTransform t;
  cv::Mat out = ResizeAndPad(image, {32, 16}, {32, 32}, PadPlacement::kTopLeft,
                             cv::Scalar::all(114), cv::INTER_LINEAR, &t);
  EXPECT_EQ(out.size(), cv::Size(32, 32));
  EXPECT_EQ(out.at<cv::Vec3b>(0, 0), cv::Vec3b(1, 2, 3));
  EXPECT_EQ(out.at<cv::Vec3b>(16, 0), cv::Vec3b(114, 114, 114));
  EXPECT_EQ(t.content, cv::Rect(0, 0, 32, 16));
  EXPECT_DOUBLE_EQ(t.scale_x, 0.8);
  out = ResizeAndPad(image, {32, 16}, {32, 33}, PadPlacement::kCentre, cv::Scalar::all(114),
                     cv::INTER_LINEAR, &t);
  // 17 rows of padding: 8 on top, 9 below (Ultralytics rounding).
  EXPECT_EQ(t.content, cv::Rect(0, 8, 32, 16));
  EXPECT_EQ(out.at<cv::Vec3b>(7, 5), cv::Vec3b(114, 114, 114));
  EXPECT_EQ(out.at<cv::Vec3b>(8, 5), cv::Vec3b(1, 2, 3));
  EXPECT_EQ(out.at<cv::Vec3b>(24, 5), cv::Vec3b(114, 114, 114));
  const cv::Point2d back = t.ToOriginal({16, 16});
  EXPECT_DOUBLE_EQ(back.x, 20.0);
  EXPECT_DOUBLE_EQ(back.y, 10.0);
}

TEST(PreprocessTest, GreyImagesBecomeThreeChannels) {
  const cv::Mat grey(4, 4, CV_8UC1, cv::Scalar(7));
  const cv::Mat out = ResizeAndPad(grey, {4, 4}, {4, 6}, PadPlacement::kTopLeft,
                                   cv::Scalar::all(0), cv::INTER_LINEAR, nullptr);
  EXPECT_EQ(out.type(), CV_8UC3);
  EXPECT_EQ(out.at<cv::Vec3b>(3, 3), cv::Vec3b(7, 7, 7));
  EXPECT_EQ(out.at<cv::Vec3b>(5, 3), cv::Vec3b(0, 0, 0));
}

TEST(PreprocessTest, BlobIsPlanarNormalisedAndOrdered) {
  cv::Mat image(1, 2, CV_8UC3);
  image.at<cv::Vec3b>(0, 0) = {10, 20, 30};  // B G R
  image.at<cv::Vec3b>(0, 1) = {40, 50, 60};
  auto rgb = ImageToBlob(image, true, {0, 10, 20}, {1, 2, 4});
  EXPECT_THAT(rgb, testing::ElementsAre(30, 60, 5, 20, -2.5, 5));
  auto bgr = ImageToBlob(image, false, {0, 0, 0}, {1, 1, 1});
  EXPECT_THAT(bgr, testing::ElementsAre(10, 40, 20, 50, 30, 60));
}

TEST(ModelArgTest, FileAndOptions) {
  auto arg = ParseModelArg("a/b.onnx,arch=yolox", {"arch"});
  EXPECT_EQ(arg.file, "a/b.onnx");
  EXPECT_EQ(arg.options.at("arch"), "yolox");
  EXPECT_EQ(ParseModelArg("odd,name.onnx", {"spec"}).file, "odd,name.onnx");
  EXPECT_EQ(ParseModelArg("m.onnx,spec=x,y.yaml", {"spec"}).options.at("spec"), "x,y.yaml");
  EXPECT_THROW(ParseModelArg("m.onnx,size=3", {"arch"}), InputError);
  EXPECT_THROW(ParseModelArg("m.onnx,arch=a,arch=b", {"arch"}), InputError);
  EXPECT_THROW(ParseModelArg("", {"arch"}), InputError);
  EXPECT_THROW(ParseModelArg(",arch=yolox", {"arch"}), InputError);
}

TEST(OrtSessionTest, InspectsAndRuns) {
  OrtSession session(kModels / "depth_dynamic.onnx", OrtSessionOptions{});
  ASSERT_EQ(session.Inputs().size(), 1u);
  EXPECT_EQ(session.Inputs()[0].name, "image");
  EXPECT_EQ(ShapeToString(session.Inputs()[0].shape), "1x3x?x?");
  EXPECT_EQ(ShapeToString(session.Outputs()[0].shape), "1x1x?x?");
  EXPECT_EQ(session.Provider(), "CPUExecutionProvider");
  const std::vector<float> input{1, 2, 3, 4, 5, 6};  // 1x3x1x2
  const auto out = session.Run(input, {1, 3, 1, 2});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].shape, (std::vector<int64_t>{1, 1, 1, 2}));
  EXPECT_THAT(out[0].data, testing::ElementsAre(3, 4));
  EXPECT_THROW(session.Run(input, {1, 3, 2, 2}), std::invalid_argument);
  // Wrong channel count: ONNX Runtime's own error, as one line naming the model.
  try {
    session.Run({1, 2, 3, 4}, {1, 4, 1, 1});
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), testing::HasSubstr("depth_dynamic.onnx: inference failed"));
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
  EXPECT_THAT(AvailableOrtProviders(), testing::Contains("CPUExecutionProvider"));
  OrtSessionOptions bad;
  bad.intra_op_threads = 0;
  EXPECT_THROW(OrtSession(kModels / "depth_dynamic.onnx", bad), std::invalid_argument);
}

}  // namespace
}  // namespace ademono
