// `ademono detect` end to end: the real YOLOX-nano model, JSON output, bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_test_util.h"

namespace {

using namespace ademono::cli_test;
namespace fs = std::filesystem;
const fs::path kShared = ADEMONO_SHARED_DIR;
const fs::path kModels = fs::path(ADEMONO_SOURCE_DIR) / "tests/data/models";

TEST(DetectCliTest, YoloxNanoJsonMatchesTheReferenceLayout) {
  const fs::path model = kShared / "models/yolox_nano.onnx";
  if (!fs::exists(model)) GTEST_SKIP() << "no " << model;
  const fs::path dir = FreshTempDir("detect_cli");
  const fs::path json_path = dir / "det.json";
  const CliResult r =
      RunCli("detect --detector model:" + model.string() + " --class-agnostic-nms --json " +
             json_path.string() + " " + (kShared / "images/bus.jpg").string() + " " +
             (kShared / "images/dog.jpg").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_THAT(r.out, testing::HasSubstr("bus.jpg: 4 detections"));
  EXPECT_THAT(r.out, testing::HasSubstr("dog.jpg: 3 detections"));
  std::ifstream in(json_path);
  const auto json = nlohmann::json::parse(in);
  const auto& bus = json["images"]["bus.jpg"];
  EXPECT_EQ(bus["width"], 810);
  EXPECT_EQ(bus["height"], 1080);
  ASSERT_EQ(bus["detections"].size(), 4u);
  EXPECT_EQ(bus["detections"][0]["class"], "bus");
  EXPECT_EQ(bus["detections"][0]["class_id"], 5);
  EXPECT_NEAR(bus["detections"][0]["score"].get<double>(), 0.903, 0.02);
  EXPECT_EQ(bus["detections"][0]["box_xywh"].size(), 4u);
  // --classes narrows the output.
  const CliResult people = RunCli("detect --detector model:" + model.string() +
                                  " --classes person " + (kShared / "images/bus.jpg").string());
  ASSERT_EQ(people.code, 0) << people.out;
  EXPECT_THAT(people.out, testing::HasSubstr("bus.jpg: 3 detections"));
  fs::remove_all(dir);
}

TEST(DetectCliTest, ConstantHeadWithArch) {
  const fs::path dir = FreshTempDir("detect_cli_head");
  const fs::path image = kShared / "images/person.jpg";
  const CliResult r = RunCli("detect --detector model:" + (kModels / "det_yolov8.onnx").string() +
                             ",arch=yolov8 " + image.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_THAT(r.out, testing::HasSubstr("person.jpg: 2 detections"));
  EXPECT_THAT(r.out, testing::HasSubstr("bicycle"));
  fs::remove_all(dir);
}

TEST(DetectCliTest, BadInputGivesOneLineErrorAndNoOutput) {
  const fs::path dir = FreshTempDir("detect_cli_bad");
  const fs::path json_path = dir / "det.json";
  const std::string image = (kShared / "images/bus.jpg").string();
  struct Case {
    std::string args;
    std::string message;
  };
  const std::vector<Case> cases{
      {"--detector model:" + (dir / "missing.onnx").string(), "missing.onnx: no such file"},
      {"--detector model:" + (kModels / "depth_metric.onnx").string(), "1x1x48x64"},
      {"--detector model:" + (kModels / "det_yolov5.onnx").string(), "arch="},
      {"--detector model:" + (kModels / "det_yolov5.onnx").string() + ",arch=yolo9",
       "unknown detector arch"},
      {"--detector model:" + (kModels / "det_yolov5.onnx").string() +
           ",arch=yolov5 --classes "
           "unicorn",
       "unknown class 'unicorn'"},
      {"--detector model:" + (kModels / "det_yolov5.onnx").string() + ",arch=yolov5 --score 2",
       "detector.score_threshold must be in [0, 1], got 2"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const CliResult r = RunCli("detect " + c.args + " --json " + json_path.string() + " " + image);
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_THAT(r.out, testing::StartsWith("ademono detect: error: "));
    EXPECT_THAT(r.out, testing::HasSubstr(c.message));
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    EXPECT_FALSE(fs::exists(json_path));
  }
  const CliResult missing_image =
      RunCli("detect --detector model:" + (kModels / "det_yolov5.onnx").string() +
             ",arch=yolov5 --json " + json_path.string() + " " + (dir / "nope.jpg").string());
  EXPECT_EQ(missing_image.code, 2);
  EXPECT_THAT(missing_image.out, testing::HasSubstr("nope.jpg"));
  EXPECT_FALSE(fs::exists(json_path));
  fs::remove_all(dir);
}

}  // namespace
