// `ademono depth` end to end on the tiny metric test model (depth = grey / 25.5 m).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "ademono/core/camera.h"
#include "cli_test_util.h"

namespace {

using namespace ademono::cli_test;
namespace fs = std::filesystem;
const fs::path kModels = fs::path(ADEMONO_SOURCE_DIR) / "tests/data/models";

class DepthCliTest : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = FreshTempDir("depth_cli");
    image_ = dir_ / "grey.png";
    cv::imwrite(image_.string(), cv::Mat(96, 128, CV_8UC3, cv::Scalar::all(51)));
    const ademono::Camera camera = ademono::Camera::Pinhole(128, 96, 100, 64, 48);
    camera_ = dir_ / "camera.yaml";
    ademono::WriteCameraYaml(camera_, camera);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Args(const fs::path& out, const std::string& model = "depth_metric.onnx") const {
    return "depth --depth model:" + (kModels / model).string() + " --camera " + camera_.string() +
           " --out " + out.string() + " " + image_.string();
  }
  fs::path dir_, image_, camera_;
};

TEST_F(DepthCliTest, WritesMillimetrePngTiffAndPreview) {
  const CliResult png = RunCli(Args(dir_ / "out/depth.png"));
  ASSERT_EQ(png.code, 0) << png.out;
  EXPECT_THAT(png.out, testing::HasSubstr("100.0% valid"));
  const cv::Mat mm = cv::imread((dir_ / "out/depth.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(mm.type(), CV_16UC1);
  EXPECT_EQ(mm.size(), cv::Size(128, 96));
  double lo, hi;
  cv::minMaxLoc(mm, &lo, &hi);
  EXPECT_EQ(lo, 2000);
  EXPECT_EQ(hi, 2000);
  const cv::Mat preview = cv::imread((dir_ / "out/depth_preview.png").string(), cv::IMREAD_COLOR);
  EXPECT_EQ(preview.size(), cv::Size(128, 96));

  const CliResult tiff = RunCli(Args(dir_ / "depth.tiff", "depth_inverse.onnx"));
  ASSERT_EQ(tiff.code, 0) << tiff.out;
  const cv::Mat metres = cv::imread((dir_ / "depth.tiff").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(metres.type(), CV_32FC1);
  EXPECT_NEAR(metres.at<float>(10, 10), 1.0f, 1e-5);  // inverse: 2 / (51 / 25.5)
  EXPECT_TRUE(fs::exists(dir_ / "depth_preview.png"));
}

TEST_F(DepthCliTest, BadInputGivesOneLineErrorAndNoOutput) {
  const fs::path out = dir_ / "bad/depth.png";
  const std::vector<std::pair<std::string, std::string>> cases{
      {Args(dir_ / "bad/depth.jpg"), "depth.jpg: --out must end in .png"},
      {Args(out, "depth_bad_output.onnx"), "1x2x48x64"},
      {Args(out, "missing.onnx"), "missing.onnx: no such file"},
      {"depth --depth model:" + (kModels / "depth_metric.onnx").string() +
           ",spec=" + (dir_ / "none.yaml").string() + " --camera " + camera_.string() + " --out " +
           out.string() + " " + image_.string(),
       "none.yaml: no such file"},
      {"depth --depth model:" + (kModels / "depth_metric.onnx").string() + " --camera " +
           (dir_ / "nocam.yaml").string() + " --out " + out.string() + " " + image_.string(),
       "nocam.yaml"},
      {"depth --depth model:" + (kModels / "depth_metric.onnx").string() + " --camera " +
           camera_.string() + " --out " + out.string() + " " + (dir_ / "nope.png").string(),
       "nope.png"},
  };
  for (const auto& [args, message] : cases) {
    SCOPED_TRACE(args);
    const CliResult r = RunCli(args);
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_THAT(r.out, testing::StartsWith("ademono depth: error: "));
    EXPECT_THAT(r.out, testing::HasSubstr(message));
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    EXPECT_FALSE(fs::exists(dir_ / "bad"));
  }
  // An image that does not match the camera.
  cv::imwrite((dir_ / "small.png").string(), cv::Mat(10, 10, CV_8UC3, cv::Scalar::all(1)));
  const CliResult mismatch =
      RunCli("depth --depth model:" + (kModels / "depth_metric.onnx").string() + " --camera " +
             camera_.string() + " --out " + out.string() + " " + (dir_ / "small.png").string());
  EXPECT_EQ(mismatch.code, 2);
  EXPECT_THAT(mismatch.out, testing::HasSubstr("image is 10x10 but the camera"));
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
}

}  // namespace
