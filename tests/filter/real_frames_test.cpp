// The dynamic filter on real 7-Scenes frames (a static scene): a "person" box over the image
// centre must remove almost nothing when the prediction is the ground-truth pose, and must remove
// the points whose previous positions we displace as if the object moved. Both with stage 1 in
// its motion-compensated form (the default) and as the paper's mean-displacement test.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cstdio>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>

#include "ademono/feature/orb_extractor.h"
#include "ademono/filter/feature_filter.h"

namespace ademono {
namespace {

std::string FramePath(int frame, const char* kind) {
  char path[512];
  std::snprintf(path, sizeof(path), "%s/data/7scenes-seq-a/frame-%06d.%s", ADEMONO_SHARED_DIR,
                frame, kind);
  return path;
}

Eigen::Matrix4d WorldFromCam(int frame) {
  std::ifstream in(FramePath(frame, "pose.txt"));
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i)
    if (!(in >> m(i / 4, i % 4)))
      throw std::runtime_error("cannot read pose " + FramePath(frame, "pose.txt"));
  return m;
}

struct RealFrame {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  std::vector<float> depths;
};

RealFrame Load(int frame) {
  const cv::Mat image = cv::imread(FramePath(frame, "color.jpg"), cv::IMREAD_GRAYSCALE);
  const cv::Mat depth = cv::imread(FramePath(frame, "depth.png"), cv::IMREAD_UNCHANGED);
  if (image.empty() || depth.empty())
    throw std::runtime_error("cannot read frame " + std::to_string(frame));
  RealFrame f;
  OrbExtractor(OrbOptions{}).Extract(image, f.keypoints, f.descriptors);
  for (const auto& kp : f.keypoints) {
    const uint16_t mm = depth.at<uint16_t>(cvRound(kp.pt.y), cvRound(kp.pt.x));
    f.depths.push_back(mm == 0 || mm == 65535 ? 0.f : mm / 1000.f);
  }
  return f;
}

Camera SevenScenesCamera() { return Camera::Pinhole(640, 480, 585, 320, 240); }

class RealFramesTest : public ::testing::TestWithParam<bool> {
 protected:
  void SetUp() override {
    prev_ = Load(0);
    cur_ = Load(3);
    const Eigen::Matrix4d world_from_cam0 = WorldFromCam(0);
    const Eigen::Matrix4d cam3_from_world = WorldFromCam(3).inverse();
    previous_.keypoints = prev_.keypoints;
    previous_.descriptors = prev_.descriptors;
    world_from_cam0_ = world_from_cam0;
    SetPreviousPoints();
    Rigid3d predicted;
    predicted.matrix() = cam3_from_world;
    predicted_ = predicted;
    Detection person;
    person.class_id = 0;
    person.class_name = "person";
    person.box = cv::Rect2f(180, 120, 280, 240);  // 22 % of the image: a large target
    detections_ = {person};
  }

  // Camera and world points of the previous keypoints from their depth (NaN without).
  void SetPreviousPoints() {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    previous_.points_world.assign(prev_.keypoints.size(), Eigen::Vector3d(nan, nan, nan));
    previous_.points_cam = previous_.points_world;
    for (size_t i = 0; i < prev_.keypoints.size(); ++i) {
      if (prev_.depths[i] <= 0) continue;
      const cv::Point2f& p = previous_.keypoints[i].pt;
      const Eigen::Vector3d cam = camera_.Unproject(Eigen::Vector2d(p.x, p.y), prev_.depths[i]);
      previous_.points_cam[i] = cam;
      previous_.points_world[i] = (world_from_cam0_ * cam.homogeneous()).head<3>();
    }
  }

  FilterInput Input() const {
    FilterInput in;
    in.camera = &camera_;
    in.keypoints = &cur_.keypoints;
    in.descriptors = &cur_.descriptors;
    in.depths = &cur_.depths;
    in.detections = &detections_;
    in.previous = &previous_;
    in.predicted_cam_from_world = predicted_;
    return in;
  }

  static FilterOptions DynamicOnly() {
    FilterOptions o;
    o.enable_enhancement = o.enable_distant_filter = false;
    o.dynamic.stage1_motion_compensation = GetParam();
    return o;
  }

  int InsideBox() const {
    int n = 0;
    for (const auto& kp : cur_.keypoints) n += detections_[0].box.contains(kp.pt) ? 1 : 0;
    return n;
  }

  Camera camera_ = SevenScenesCamera();
  RealFrame prev_, cur_;
  PreviousFrameFeatures previous_;
  std::optional<Rigid3d> predicted_;
  Eigen::Matrix4d world_from_cam0_ = Eigen::Matrix4d::Identity();
  std::vector<Detection> detections_;
};

TEST_P(RealFramesTest, StaticSceneKeepsAlmostEverythingInTheBox) {
  FeatureFilter filter(DynamicOnly());
  FilterStats stats;
  filter.Apply(Input(), &stats);
  EXPECT_EQ(stats.boxes_large, 1);
  EXPECT_EQ(stats.stage1_ran, 1);
  EXPECT_EQ(stats.stage1_compensated, GetParam() ? 1 : 0);
  const int inside = InsideBox();
  RecordProperty("inside", inside);
  RecordProperty("stage1", stats.removed_stage1);
  RecordProperty("stage2", stats.removed_stage2);
  ASSERT_GT(inside, 200);
  EXPECT_LT(stats.removed_stage1 + stats.removed_stage2, inside / 10)
      << stats.removed_stage1 << " + " << stats.removed_stage2 << " of " << inside;
}

TEST_P(RealFramesTest, DisplacedPointsInTheBoxAreRemovedByStageOne) {
  // Pretend the object moved 25 px to the left: shift the previous positions of every keypoint
  // whose match lands in the box (we shift all previous keypoints inside the box region), and
  // their 3D points with them.
  for (auto& kp : previous_.keypoints)
    if (detections_[0].box.contains(kp.pt)) kp.pt.x += 25.f;
  SetPreviousPoints();
  FeatureFilter filter(DynamicOnly());
  FilterStats stats;
  filter.Apply(Input(), &stats);
  const int inside = InsideBox();
  RecordProperty("stage1_moved", stats.removed_stage1);
  EXPECT_GT(stats.removed_stage1, inside / 2) << stats.removed_stage1 << " of " << inside;
}

INSTANTIATE_TEST_SUITE_P(Stage1, RealFramesTest, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? "MotionCompensated" : "PaperMeanDisplacement";
                         });

}  // namespace
}  // namespace ademono
