#include "ademono/detect/detector_factory.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "ademono/core/error.h"
#include "ademono/detect/detection_io.h"

namespace ademono {
namespace {

namespace fs = std::filesystem;
const fs::path kModels = fs::path(ADEMONO_SOURCE_DIR) / "tests/data/models";

Detection MakeDetection(int class_id, float x) {
  Detection d;
  d.class_id = class_id;
  d.class_name = CocoClassNames()[class_id];
  d.score = 0.9f;
  d.box = {x, 1, 2, 3};
  return d;
}

class CacheDetectorTest : public testing::Test {
 protected:
  void SetUp() override {
    path_ = fs::temp_directory_path() /
            ("ademono_detector_factory_test_" + std::to_string(::getpid()) + ".jsonl");
    std::vector<FrameDetections> frames(3);
    for (size_t i = 0; i < frames.size(); ++i) {
      frames[i].frame = i;
      frames[i].timestamp = 10.0 + i;
      frames[i].name = "img" + std::to_string(i);
      frames[i].detections = {MakeDetection(0, 10.f * i), MakeDetection(16, 5.f)};  // person, dog
    }
    WriteDetectionsJsonl(path_, frames);
  }
  void TearDown() override { fs::remove(path_); }
  fs::path path_;
};

TEST_F(CacheDetectorTest, MatchesByNameThenTimestampThenIndex) {
  auto detector = MakeDetector("cache:" + path_.string(), DetectorOptions{});
  EXPECT_EQ(detector->Name(), "cache:" + path_.string());
  FrameData frame;
  frame.name = "img2";  // by name, even with another index and timestamp
  frame.index = 0;
  frame.timestamp = 10.0;
  auto detections = detector->Detect(frame);
  ASSERT_EQ(detections.size(), 1u);  // default classes drop the dog
  EXPECT_FLOAT_EQ(detections[0].box.x, 20.f);
  frame.name = "other";
  frame.timestamp = 11.0005;  // within 1 ms of frame 1
  EXPECT_FLOAT_EQ(detector->Detect(frame)[0].box.x, 10.f);
  frame.timestamp = 99.0;
  frame.index = 2;  // by index
  EXPECT_FLOAT_EQ(detector->Detect(frame)[0].box.x, 20.f);
  frame.index = 7;
  try {
    detector->Detect(frame);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), testing::HasSubstr(path_.string() + ": no detections for frame 7"));
  }
}

TEST_F(CacheDetectorTest, ClassFilter) {
  DetectorOptions all;
  all.class_ids.clear();
  auto detector = MakeDetector("cache:" + path_.string(), all);
  FrameData frame;
  frame.name = "img0";
  EXPECT_EQ(detector->Detect(frame).size(), 2u);
}

TEST(DetectorFactoryTest, KindsAndErrors) {
  EXPECT_EQ(MakeDetector("none", DetectorOptions{})->Name(), "none");
  EXPECT_TRUE(MakeDetector("none", DetectorOptions{})->Detect(FrameData{}).empty());
  EXPECT_THROW(MakeDetector("yolo", DetectorOptions{}), InputError);
  EXPECT_THROW(MakeDetector("cache:", DetectorOptions{}), InputError);
  EXPECT_THROW(MakeDetector("cache:/no/such/file.jsonl", DetectorOptions{}), InputError);
  const std::string v8 = (kModels / "det_yolov8.onnx").string();
  EXPECT_EQ(MakeDetector("model:" + v8 + ",arch=yolov8", DetectorOptions{})->Name(),
            "model:" + v8 + ",arch=yolov8");
  EXPECT_THAT(
      [&] {
        try {
          MakeDetector("model:" + v8 + ",arch=yolov9", DetectorOptions{});
        } catch (const InputError& e) {
          return std::string(e.what());
        }
        return std::string();
      }(),
      testing::HasSubstr("unknown detector arch 'yolov9'"));
  EXPECT_THROW(MakeDetector("model:" + v8 + ",size=3", DetectorOptions{}), InputError);
  DetectorOptions bad;
  bad.score_threshold = 1.5f;
  EXPECT_THROW(MakeDetector("none", bad), InputError);
}

TEST(DetectorOptionsTest, Check) {
  DetectorOptions options;
  EXPECT_NO_THROW(options.Check());
  options.nms_iou = 0.f;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = DetectorOptions{};
  options.class_ids = {-1};
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = DetectorOptions{};
  options.num_threads = 0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

TEST(ParseClassListTest, NamesIdsAndKeywords) {
  EXPECT_TRUE(ParseClassList("all").empty());
  EXPECT_EQ(ParseClassList("dynamic"), DefaultDynamicClassIds());
  EXPECT_EQ(ParseClassList("person, car,7,car"), (std::vector<int>{0, 2, 7}));
  EXPECT_EQ(ParseClassList("traffic light"), std::vector<int>{9});
  EXPECT_THROW(ParseClassList("unicorn"), InputError);
  EXPECT_THROW(ParseClassList("80"), InputError);
  EXPECT_THROW(ParseClassList("person,,car"), InputError);
  EXPECT_THROW(ParseClassList(""), InputError);
}

}  // namespace
}  // namespace ademono
