#include "ademono/depth/cache_depth.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "ademono/core/error.h"
#include "ademono/depth/depth_factory.h"

namespace ademono {
namespace {

namespace fs = std::filesystem;

class CacheDepthTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string name = "ademono_cache_depth_";
    name += std::to_string(::getpid());
    dir_ = fs::temp_directory_path() / name;
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(CacheDepthTest, ReadsPngMillimetresByStem) {
  cv::Mat mm(4, 6, CV_16UC1, cv::Scalar(1500));
  mm.at<uint16_t>(0, 0) = 0;
  mm.at<uint16_t>(0, 1) = 65535;
  ASSERT_TRUE(cv::imwrite((dir_ / "frame-000003.depth.png").string(), mm));
  CacheDepthProvider provider(dir_);
  FrameData frame;
  frame.name = "frame-000003.color";
  frame.timestamp = 0.1;
  frame.image = cv::Mat(4, 6, CV_8UC3);
  const cv::Mat depth = provider.Depth(frame, Camera{});
  ASSERT_EQ(depth.type(), CV_32FC1);
  EXPECT_FLOAT_EQ(depth.at<float>(2, 2), 1.5f);
  EXPECT_FLOAT_EQ(depth.at<float>(0, 0), 0.f);
  EXPECT_FLOAT_EQ(depth.at<float>(0, 1), 0.f);
}

TEST_F(CacheDepthTest, ReadsFloatTiffMetresByTimestampAndResizes) {
  cv::Mat m(2, 3, CV_32FC1, cv::Scalar(2.25f));
  m.at<float>(1, 2) = -1.f;
  ASSERT_TRUE(cv::imwrite((dir_ / "1305031102.175304.tiff").string(), m));
  CacheDepthProvider provider(dir_);
  FrameData frame;
  frame.name = "rgb_other_name";
  frame.timestamp = 1305031102.1758;  // within 1 ms
  frame.image = cv::Mat(4, 6, CV_8UC3);
  const cv::Mat depth = provider.Depth(frame, Camera{});
  EXPECT_EQ(depth.size(), cv::Size(6, 4));
  EXPECT_FLOAT_EQ(depth.at<float>(0, 0), 2.25f);
  EXPECT_FLOAT_EQ(depth.at<float>(3, 5), 0.f);

  frame.timestamp = 1305031102.178;  // 2.7 ms away: no match
  try {
    provider.Depth(frame, Camera{});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(dir_.string()), std::string::npos) << message;
    EXPECT_NE(message.find("rgb_other_name"), std::string::npos) << message;
  }
}

TEST_F(CacheDepthTest, RejectsEmptyFolderAndBadFiles) {
  EXPECT_THROW(CacheDepthProvider provider(dir_), InputError);
  EXPECT_THROW(CacheDepthProvider provider(dir_ / "missing"), InputError);
  cv::Mat rgb(2, 2, CV_8UC3, cv::Scalar::all(1));
  ASSERT_TRUE(cv::imwrite((dir_ / "image_a.png").string(), rgb));
  CacheDepthProvider provider(dir_);
  FrameData frame;
  frame.name = "image_a";
  EXPECT_THROW(provider.Depth(frame, Camera{}), InputError);  // three channels
  { std::ofstream(dir_ / "image_b.png") << "not an image"; }
  CacheDepthProvider provider2(dir_);
  frame.name = "image_b";
  EXPECT_THROW(provider2.Depth(frame, Camera{}), InputError);
}

// A cache that says which network made it (`ademono batch` writes these) is that network's depth
// for `run`: the same settings family and error model as model:FILE; the maps come from DIR.
TEST_F(CacheDepthTest, CacheOfANetworkIsDescribedAsThatNetwork) {
  const std::string spec =
      (fs::path(ADEMONO_SOURCE_DIR) / "configs" / "models" / "fastdepth_nyu.yaml").string();
  const DepthSourceInfo model = DescribeDepthSource("model:/models/fastdepth.onnx,spec=" + spec);
  const DepthSourceInfo cache =
      DescribeDepthSource("cache:" + dir_.string() + ",model=/models/fastdepth.onnx,spec=" + spec);
  EXPECT_TRUE(cache.network);
  EXPECT_EQ(cache.domain, "indoor");
  EXPECT_TRUE(cache.error_model.Enabled());
  EXPECT_EQ(cache.error_model, model.error_model);
  EXPECT_FALSE(DescribeDepthSource("cache:" + dir_.string()).network);

  cv::Mat mm(4, 6, CV_16UC1, cv::Scalar(2500));
  ASSERT_TRUE(cv::imwrite((dir_ / "f1.png").string(), mm));
  DepthFactoryContext context;
  const auto provider = MakeDepthProvider(
      "cache:" + dir_.string() + ",model=/models/fastdepth.onnx,spec=" + spec, context);
  FrameData frame;
  frame.name = "f1";
  frame.image = cv::Mat(4, 6, CV_8UC3);
  EXPECT_FLOAT_EQ(provider->Depth(frame, Camera{}).at<float>(1, 1), 2.5f);
}

TEST_F(CacheDepthTest, OnlyPngAndTiffContentIsDecoded) {
  // OpenCV picks the decoder by content: a BMP (or JPEG 2000, PFM, ...) named .png must not
  // reach a decoder the depth format does not document.
  const fs::path path = dir_ / "frame-000001.png";
  ASSERT_TRUE(cv::imwrite((dir_ / "frame.bmp").string(), cv::Mat(4, 6, CV_8UC1, cv::Scalar(3))));
  fs::rename(dir_ / "frame.bmp", path);
  try {
    ReadDepthMap(path);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              path.string() + ": depth map must be 16-bit PNG (mm) or 32-bit float TIFF (m)");
  }
}

}  // namespace
}  // namespace ademono
