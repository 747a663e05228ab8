// The real YOLOX-nano model on real photos must reproduce the reference decoder's detections
// (../shared/images/expected_detections.json, made with OpenCV DNN).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "ademono/core/file_util.h"
#include "ademono/detect/yolo_detector.h"

namespace ademono {
namespace {

const std::filesystem::path kShared = ADEMONO_SHARED_DIR;

float IouOf(const cv::Rect2f& a, const cv::Rect2f& b) {
  const float inter = (a & b).area();
  return inter / (a.area() + b.area() - inter);
}

TEST(YoloxReferenceTest, ReproducesExpectedDetections) {
  const auto model = kShared / "models/yolox_nano.onnx";
  if (!std::filesystem::exists(model)) GTEST_SKIP() << "no " << model;
  std::ifstream in(kShared / "images/expected_detections.json");
  const auto expected = nlohmann::json::parse(in);
  DetectorOptions options;
  options.score_threshold = expected["score_threshold"].get<float>();
  options.nms_iou = expected["nms_iou"].get<float>();
  options.class_ids.clear();  // all 80 classes
  options.class_agnostic_nms = true;
  YoloDetector detector(model, YoloArch::kAuto, options);
  EXPECT_EQ(detector.Arch(), YoloArch::kYolox);
  EXPECT_EQ(detector.InputSize(), cv::Size(416, 416));
  for (const auto& [file, image_json] : expected["images"].items()) {
    SCOPED_TRACE(file);
    const cv::Mat image = ReadImage(kShared / "images" / file, cv::IMREAD_COLOR);
    ASSERT_EQ(image.cols, image_json["width"].get<int>());
    const auto detections = detector.DetectImage(image);
    const auto& want = image_json["detections"];
    EXPECT_EQ(detections.size(), want.size());
    std::vector<bool> used(detections.size(), false);
    for (const auto& w : want) {
      const auto box = w["box_xywh"].get<std::vector<float>>();
      const cv::Rect2f want_box(box[0], box[1], box[2], box[3]);
      int best = -1;
      float best_iou = 0.f;
      for (size_t i = 0; i < detections.size(); ++i) {
        if (used[i] || detections[i].class_id != w["class_id"].get<int>()) continue;
        const float iou = IouOf(detections[i].box, want_box);
        if (iou > best_iou) best_iou = iou, best = static_cast<int>(i);
      }
      ASSERT_GE(best, 0) << "no " << w["class"] << " detection for " << w.dump();
      used[best] = true;
      EXPECT_GE(best_iou, 0.9f) << w.dump();
      EXPECT_NEAR(detections[best].score, w["score"].get<float>(), 0.02f) << w.dump();
      EXPECT_EQ(detections[best].class_name, w["class"].get<std::string>());
    }
  }
}

}  // namespace
}  // namespace ademono

namespace ademono {
namespace {

// Detect() is documented as deterministic and safe from worker threads: two threads sharing one
// detector must get exactly the single-threaded result.
TEST(YoloxReferenceTest, ConcurrentCallsGiveIdenticalResults) {
  const auto model = kShared / "models/yolox_nano.onnx";
  if (!std::filesystem::exists(model)) GTEST_SKIP() << "no " << model;
  DetectorOptions options;
  options.class_ids.clear();
  YoloDetector detector(model, YoloArch::kAuto, options);
  const cv::Mat image = ReadImage(kShared / "images/street.png", cv::IMREAD_COLOR);
  const auto reference = detector.DetectImage(image);
  ASSERT_FALSE(reference.empty());
  std::vector<std::vector<Detection>> results(2);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < results.size(); ++t) {
    threads.emplace_back([&, t] { results[t] = detector.DetectImage(image); });
  }
  for (auto& thread : threads) thread.join();
  for (const auto& result : results) {
    ASSERT_EQ(result.size(), reference.size());
    for (size_t i = 0; i < result.size(); ++i) {
      EXPECT_EQ(result[i].class_id, reference[i].class_id);
      EXPECT_EQ(result[i].score, reference[i].score);
      EXPECT_EQ(result[i].box, reference[i].box);
    }
  }
}

}  // namespace
}  // namespace ademono
