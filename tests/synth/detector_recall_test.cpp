// Recall of detections against ground-truth boxes: IoU threshold, one-to-one matching, classes.
#include "ademono/synth/detector_recall.h"

#include <gtest/gtest.h>

namespace ademono::synth {
namespace {

Detection Box(int class_id, float x, float y, float w, float h) {
  Detection d;
  d.class_id = class_id;
  d.class_name = class_id == 0 ? "person" : class_id == 2 ? "car" : "truck";
  d.score = 1.f;
  d.box = cv::Rect2f(x, y, w, h);
  return d;
}

FrameDetections Frame(const std::string& name, std::vector<Detection> detections) {
  FrameDetections f;
  f.name = name;
  f.detections = std::move(detections);
  return f;
}

TEST(DetectorRecallTest, CountsTrueBoxesFoundAtTheIouThreshold) {
  EXPECT_DOUBLE_EQ(BoxIou(cv::Rect2f(0, 0, 10, 10), cv::Rect2f(5, 0, 10, 10)), 50.0 / 150.0);
  EXPECT_DOUBLE_EQ(BoxIou(cv::Rect2f(0, 0, 10, 10), cv::Rect2f(20, 0, 10, 10)), 0.0);
  const std::vector<FrameDetections> truth{
      // Two persons side by side and a car.
      Frame("a", {Box(0, 0, 0, 10, 20), Box(0, 10, 0, 10, 20), Box(2, 50, 50, 40, 20)}),
      // A person the detector misses (its frame has no detections at all).
      Frame("b", {Box(0, 0, 0, 10, 20)}),
  };
  const std::vector<FrameDetections> detected{
      // One box spanning both persons (IoU 0.5 with each: only one may take it), and the car
      // boxed as a truck (matched as a car), and a spurious person.
      Frame("a", {Box(0, 0, 0, 20, 20), Box(7, 50, 50, 40, 20), Box(0, 100, 100, 5, 5)}),
      Frame("unrelated", {Box(0, 0, 0, 10, 20)}),
  };
  const RecallResult r = DetectorRecall(truth, detected, 0.5);
  EXPECT_EQ(r.frames, 2);
  ASSERT_EQ(r.classes.count(0), 1u);
  EXPECT_EQ(r.classes.at(0).truth, 3);
  EXPECT_EQ(r.classes.at(0).found, 1);
  EXPECT_EQ(r.classes.at(0).detected, 2);
  EXPECT_NEAR(r.classes.at(0).Recall(), 1.0 / 3.0, 1e-12);
  EXPECT_EQ(r.classes.at(2).truth, 1);
  EXPECT_EQ(r.classes.at(2).found, 1);
  EXPECT_EQ(r.classes.at(7).detected, 1);
  EXPECT_EQ(r.classes.at(7).truth, 0);
  // A stricter threshold loses the half-overlapping person.
  EXPECT_EQ(DetectorRecall(truth, detected, 0.51).classes.at(0).found, 0);
  const auto json = r.ToJson();
  EXPECT_EQ(json["truth_boxes"], 4);
  EXPECT_EQ(json["found"], 2);
  EXPECT_NE(r.Markdown().find("| person | 3 | 1 | 0.333 | 2 |"), std::string::npos);
}

TEST(DetectorRecallTest, GroupsByLabel) {
  const std::vector<FrameDetections> truth{
      Frame("a", {Box(0, 0, 0, 10, 20), Box(0, 30, 0, 10, 20)}),
      Frame("b", {Box(0, 0, 0, 10, 20), Box(0, 30, 0, 10, 20)}),
  };
  const std::vector<FrameDetections> detected{
      Frame("a", {Box(0, 0, 0, 10, 20), Box(0, 30, 0, 10, 20)}),
      Frame("b", {Box(0, 1, 0, 10, 20)}),
  };
  const std::vector<std::vector<std::string>> labels{{"walker", "mannequin"},
                                                     {"walker", "mannequin"}};
  const RecallResult r = DetectorRecall(truth, detected, 0.5, &labels);
  EXPECT_EQ(r.groups.at("walker").found, 2);
  EXPECT_EQ(r.groups.at("mannequin").found, 1);
  EXPECT_EQ(r.groups.at("mannequin").truth, 2);
  const std::vector<std::vector<std::string>> wrong{{"walker"}};
  EXPECT_THROW(DetectorRecall(truth, detected, 0.5, &wrong), std::invalid_argument);
}

}  // namespace
}  // namespace ademono::synth
