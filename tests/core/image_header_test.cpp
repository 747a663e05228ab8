#include "ademono/core/image_header.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"

namespace ademono {
namespace {

namespace fs = std::filesystem;

class ImageHeaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("ademono_image_header_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path Write(const std::string& name, const std::string& bytes) {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  std::string Error(const fs::path& path) {
    try {
      ReadImage(path, cv::IMREAD_UNCHANGED);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "expected InputError for " << path;
    return {};
  }
  fs::path dir_;
};

// A PNG signature and IHDR chunk declaring `width` x `height`, and nothing else.
std::string PngHead(uint32_t width, uint32_t height) {
  std::string bytes("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR", 16);
  for (uint32_t v : {width, height}) {
    for (int shift = 24; shift >= 0; shift -= 8) bytes += static_cast<char>((v >> shift) & 0xFF);
  }
  return bytes + std::string("\x10\0\0\0\0\0\0\0\0", 9);
}

TEST_F(ImageHeaderTest, ReadsTheSizeOfWhatOpenCvWrites) {
  const cv::Mat gray16(37, 53, CV_16UC1, cv::Scalar(1000));
  const cv::Mat depth32(21, 8, CV_32FC1, cv::Scalar(2.5f));
  const cv::Mat color(19, 45, CV_8UC3, cv::Scalar(10, 20, 30));
  struct Case {
    std::string name;
    cv::Mat image;
    ImageFormat format;
  };
  for (const Case& c :
       {Case{"a.png", gray16, ImageFormat::kPng}, Case{"b.tiff", depth32, ImageFormat::kTiff},
        Case{"c.jpg", color, ImageFormat::kJpeg}}) {
    const fs::path path = dir_ / c.name;
    ASSERT_TRUE(cv::imwrite(path.string(), c.image));
    const auto header = ReadImageHeader(path);
    ASSERT_TRUE(header.has_value()) << c.name;
    EXPECT_EQ(header->format, c.format) << c.name;
    EXPECT_EQ(header->width, c.image.cols) << c.name;
    EXPECT_EQ(header->height, c.image.rows) << c.name;
    EXPECT_EQ(ReadImage(path, cv::IMREAD_UNCHANGED).size(), c.image.size()) << c.name;
  }
  // Fill bytes and a standalone marker before the frame header do not end the walk.
  std::string jpeg;
  {
    std::vector<uchar> bytes;
    ASSERT_TRUE(cv::imencode(".jpg", color, bytes));
    jpeg.assign(bytes.begin(), bytes.end());
  }
  const auto padded =
      Write("e.jpg", jpeg.substr(0, 2) + std::string("\xFF\xFF\xFF\x01", 4) + jpeg.substr(2));
  ASSERT_TRUE(ReadImageHeader(padded).has_value());
  EXPECT_EQ(ReadImageHeader(padded)->width, color.cols);
  ASSERT_TRUE(cv::imwrite((dir_ / "d.bmp").string(), color));
  EXPECT_FALSE(ReadImageHeader(dir_ / "d.bmp").has_value());  // other formats: OpenCV decides
}

TEST_F(ImageHeaderTest, AHugeDeclaredSizeIsRefusedBeforeDecoding) {
  // fuzz_depth_image (CI, 2026-11-30): a few bytes declaring a gigapixel image made OpenCV
  // allocate past the fuzzer's 2 GB limit.
  EXPECT_EQ(Error(Write("big.png", PngHead(40000, 30000))),
            (dir_ / "big.png").string() +
                ": PNG header declares a 40000 x 30000 image; the limit is 67108864 pixels");
  EXPECT_THAT(Error(Write("wide.png", PngHead(0xFFFFFFFFu, 1))),
              testing::HasSubstr("4294967295 x 1 image; the limit"));
  // A TIFF (little-endian) whose first directory declares 65535 x 65535 (SHORT values).
  std::string tiff("II*\0\x08\0\0\0\x02\0", 10);
  tiff += std::string("\0\x01\x03\0\x01\0\0\0\xFF\xFF\0\0", 12);
  tiff += std::string("\x01\x01\x03\0\x01\0\0\0\xFF\xFF\0\0", 12);
  tiff += std::string("\0\0\0\0", 4);
  EXPECT_THAT(Error(Write("big.tiff", tiff)),
              testing::HasSubstr("TIFF header declares a 65535 x 65535 image; the limit"));
}

TEST_F(ImageHeaderTest, TruncatedOrEmptyHeadersNameTheFile) {
  EXPECT_EQ(Error(Write("cut.png", PngHead(10, 10).substr(0, 20))),
            (dir_ / "cut.png").string() + ": truncated image header: PNG IHDR");
  EXPECT_THAT(Error(Write("zero.png", PngHead(0, 10))),
              testing::HasSubstr("PNG header declares a 0 x 10 image"));
  EXPECT_THAT(Error(Write("cut.tiff", std::string("MM\0*\0\0\x10\0", 8))),
              testing::HasSubstr("truncated image header: TIFF directory"));
  EXPECT_THAT(Error(Write("cut.jpg", std::string("\xFF\xD8\xFF\xE0\0\x10JFIF", 10))),
              testing::HasSubstr("truncated image header: JPEG marker"));
  // fuzz_depth_image: a classic TIFF entry typed LONG8 has no 8-byte value field to read.
  std::string long8("II*\0\x08\0\0\0\x01\0", 10);
  long8 += std::string("\0\x01\x10\0\x01\0\0\0\x10\0\0\0", 12);
  EXPECT_THAT(Error(Write("long8.tiff", long8)),
              testing::HasSubstr("TIFF image size tag has type 16"));
  EXPECT_THAT(Error(Write("junk.png", "not an image")),
              testing::HasSubstr("image does not decode"));
}

}  // namespace
}  // namespace ademono
