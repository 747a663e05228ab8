#include "ademono/perception/detection_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "ademono/core/error.h"

namespace ademono {
namespace {

namespace fs = std::filesystem;

class DetectionIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("ademono_detection_io_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path WriteText(const std::string& text) {
    const fs::path path = dir_ / "det.jsonl";
    std::ofstream(path) << text;
    return path;
  }

  // The InputError message for reading `text`, or "" if it parsed.
  std::string ReadError(const std::string& text) {
    const fs::path path = WriteText(text);
    try {
      ReadDetectionsJsonl(path);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

TEST_F(DetectionIoTest, RoundTripIsExact) {
  std::vector<FrameDetections> frames(3);
  frames[0] = {0, 1305031102.175304, "1305031102.175304", {}};
  frames[1].frame = 1;
  frames[1].timestamp = 0.0333333;
  frames[1].name = "frame-000001";
  frames[1].detections.push_back({0, "person", 0.93f, cv::Rect2f(10.25f, 20.5f, 100.125f, 200.f)});
  frames[1].detections.push_back({2, "car", 1.f, cv::Rect2f(0.f, 0.f, 1240.f, 375.3f)});
  frames[2].frame = 5;
  frames[2].detections.push_back({1, "bicycle", 0.301f, cv::Rect2f(1.f / 3.f, 2.f, 3.f, 4.f)});
  const fs::path path = dir_ / "sub" / "out.jsonl";
  WriteDetectionsJsonl(path, frames);

  const auto read = ReadDetectionsJsonl(path);
  ASSERT_EQ(read.size(), frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(read[i].frame, frames[i].frame);
    EXPECT_EQ(read[i].timestamp, frames[i].timestamp);
    EXPECT_EQ(read[i].name, frames[i].name);
    ASSERT_EQ(read[i].detections.size(), frames[i].detections.size());
    for (size_t k = 0; k < frames[i].detections.size(); ++k) {
      const Detection& a = frames[i].detections[k];
      const Detection& b = read[i].detections[k];
      EXPECT_EQ(b.class_id, a.class_id);
      EXPECT_EQ(b.class_name, a.class_name);
      EXPECT_EQ(b.score, a.score);
      EXPECT_EQ(b.box.x, a.box.x);
      EXPECT_EQ(b.box.y, a.box.y);
      EXPECT_EQ(b.box.width, a.box.width);
      EXPECT_EQ(b.box.height, a.box.height);
    }
  }
  // Floats are written as their shortest decimal, not as widened doubles.
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::getline(in, line);
  EXPECT_NE(line.find("\"score\":0.93"), std::string::npos) << line;
  EXPECT_EQ(line.find("0.9300000"), std::string::npos) << line;
  EXPECT_EQ(line.find("{\"frame\":1,\"timestamp\""), 0u) << line;
}

TEST_F(DetectionIoTest, ReadsDocumentedFormatAndFillsClassName) {
  const fs::path path = WriteText(
      "{\"frame\": 12, \"timestamp\": 0.4, \"name\": \"frame-000012\",\n"
      "\n"
      "{\"frame\": 13, \"detections\": [{\"class_id\": 2, \"score\": 0.5, "
      "\"box_xywh\": [1, 2, 3, 4]}]}\n");
  // The first line is cut: strict parsing reports it.
  EXPECT_THROW(ReadDetectionsJsonl(path), InputError);

  const fs::path good = WriteText(
      "{\"frame\": 12, \"timestamp\": 0.4, \"name\": \"frame-000012\", \"detections\": "
      "[{\"class_id\": 0, \"class\": \"person\", \"score\": 0.93, \"box_xywh\": [1, 2, 3, 4]}]}\r\n"
      "\n"
      "{\"frame\": 13, \"detections\": [{\"class_id\": 2, \"score\": 0.5, "
      "\"box_xywh\": [1.5, 2, 3, 4]}]}\n");
  const auto frames = ReadDetectionsJsonl(good);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].frame, 12u);
  EXPECT_DOUBLE_EQ(frames[0].timestamp, 0.4);
  EXPECT_EQ(frames[0].name, "frame-000012");
  ASSERT_EQ(frames[0].detections.size(), 1u);
  EXPECT_FLOAT_EQ(frames[0].detections[0].box.height, 4.f);
  ASSERT_EQ(frames[1].detections.size(), 1u);
  EXPECT_EQ(frames[1].detections[0].class_name, "car");
  EXPECT_FLOAT_EQ(frames[1].detections[0].box.x, 1.5f);
}

TEST_F(DetectionIoTest, ErrorsNameFileAndLine) {
  const std::string file = (dir_ / "det.jsonl").string();
  const std::string ok = "{\"frame\": 0, \"detections\": []}\n";
  EXPECT_EQ(ReadError(ok), "");
  EXPECT_EQ(
      ReadError(ok + "{\"frame\": 1, \"detections\": [\n").rfind(file + ":2: not valid JSON: ", 0),
      0u);
  // A number beyond a double is nlohmann's out_of_range, not a parse_error (found by fuzzing).
  EXPECT_EQ(ReadError("{\"frame\": 0, \"x\": [2016e7776], \"detections\": []}\n")
                .rfind(file + ":1: not valid JSON: number overflow", 0),
            0u);
  EXPECT_EQ(ReadError(ok + "[1, 2]\n"), file + ":2: expected a JSON object per line");
  EXPECT_EQ(ReadError("{\"detections\": []}\n"), file + ":1: missing \"frame\"");
  EXPECT_EQ(ReadError("{\"frame\": -1, \"detections\": []}\n"),
            file + ":1: \"frame\" must be a non-negative integer");
  EXPECT_EQ(ReadError("{\"frame\": 0}\n"), file + ":1: missing \"detections\"");
  EXPECT_EQ(ReadError(ok + ok),
            file + ":2: frame 0 does not follow frame 0 (frames must increase)");
  EXPECT_EQ(ReadError("{\"frame\": 0, \"timestamp\": \"x\", \"detections\": []}\n"),
            file + ":1: \"timestamp\" is not a number");
  const std::string prefix = "{\"frame\": 0, \"detections\": [";
  EXPECT_EQ(ReadError(prefix + "{\"class_id\": 80, \"score\": 1, \"box_xywh\": [0,0,1,1]}]}\n"),
            file + ":1: detection 0: \"class_id\" must be an integer in [0, 80)");
  EXPECT_EQ(ReadError(prefix + "{\"class_id\": 0, \"score\": 1.5, \"box_xywh\": [0,0,1,1]}]}\n"),
            file + ":1: detection 0: \"score\" must be in [0, 1]");
  EXPECT_EQ(ReadError(prefix + "{\"class_id\": 0, \"score\": 1, \"box_xywh\": [0,0,1]}]}\n"),
            file + ":1: detection 0: \"box_xywh\" must be an array of 4 numbers");
  EXPECT_EQ(ReadError(prefix + "{\"class_id\": 0, \"score\": 1, \"box_xywh\": [0,0,-1,1]}]}\n"),
            file + ":1: detection 0: box width and height must be >= 0");
  EXPECT_EQ(ReadError(prefix + "{\"class_id\": 0, \"score\": 1, \"box_xywh\": [0,\"a\",1,1]}]}\n"),
            file + ":1: detection 0: \"box_xywh\"[1] is not a number");
  EXPECT_EQ(ReadError(prefix + "{\"class_id\": 0, \"box_xywh\": [0,0,1,1]}]}\n"),
            file + ":1: missing \"score\"");
  EXPECT_EQ(ReadError("\n\n"), file + ": no frames (empty detections file)");
  try {
    ReadDetectionsJsonl(dir_ / "missing.jsonl");
    FAIL() << "missing file read";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), (dir_ / "missing.jsonl").string() + ": no such file");
  }
}

TEST_F(DetectionIoTest, WriterRejectsUnorderedFramesAndLeavesNoFile) {
  std::vector<FrameDetections> frames(2);
  frames[0].frame = 3;
  frames[1].frame = 2;
  const fs::path path = dir_ / "bad.jsonl";
  EXPECT_THROW(WriteDetectionsJsonl(path, frames), std::invalid_argument);
  EXPECT_FALSE(fs::exists(path));
}

TEST(CocoClassNames, EightyInModelOrder) {
  const auto& names = CocoClassNames();
  ASSERT_EQ(names.size(), 80u);
  EXPECT_EQ(names[0], "person");
  EXPECT_EQ(names[1], "bicycle");
  EXPECT_EQ(names[2], "car");
  EXPECT_EQ(names[3], "motorcycle");
  EXPECT_EQ(names[5], "bus");
  EXPECT_EQ(names[7], "truck");
  EXPECT_EQ(names[79], "toothbrush");
}

}  // namespace
}  // namespace ademono
