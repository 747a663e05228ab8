#include "ademono/depth/sensor_depth.h"

#include <gtest/gtest.h>

#include "ademono/core/error.h"
#include "ademono/depth/depth_factory.h"

namespace ademono {
namespace {

// A minimal in-memory sequence to check the dataset-level error.
class FakeSequence : public Sequence {
 public:
  explicit FakeSequence(bool has_depth) : has_depth_(has_depth) {}
  std::string Kind() const override { return "kitti"; }
  std::filesystem::path Path() const override { return "/data/kitti/00"; }
  size_t Size() const override { return 1; }
  const Camera& GetCamera() const override { return camera_; }
  bool HasDepth() const override { return has_depth_; }
  bool HasGroundTruth() const override { return false; }
  FrameData Load(size_t) const override { return {}; }
  double Timestamp(size_t) const override { return 0; }

 private:
  bool has_depth_;
  Camera camera_;
};

TEST(SensorDepthTest, PassesFrameDepthThroughAndClearsInvalidValues) {
  SensorDepthProvider provider(nullptr);
  FrameData frame;
  frame.image = cv::Mat(2, 2, CV_8UC3, cv::Scalar::all(0));
  frame.depth = (cv::Mat_<float>(2, 2) << 1.5f, std::numeric_limits<float>::quiet_NaN(), -1.f, 0.f);
  const cv::Mat depth = provider.Depth(frame, Camera{});
  EXPECT_FLOAT_EQ(depth.at<float>(0, 0), 1.5f);
  EXPECT_FLOAT_EQ(depth.at<float>(0, 1), 0.f);
  EXPECT_FLOAT_EQ(depth.at<float>(1, 0), 0.f);
  EXPECT_EQ(provider.Name(), "sensor");
}

TEST(SensorDepthTest, ErrorsNameTheDatasetOrFrame) {
  FakeSequence no_depth(false);
  try {
    SensorDepthProvider provider(&no_depth);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/data/kitti/00"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no sensor depth"), std::string::npos) << e.what();
  }
  SensorDepthProvider provider(nullptr);
  FrameData frame;
  frame.name = "frame-000007";
  frame.index = 7;
  frame.image = cv::Mat(2, 2, CV_8UC3);
  EXPECT_THROW(provider.Depth(frame, Camera{}), InputError);
  frame.depth = cv::Mat(3, 3, CV_32FC1, cv::Scalar(1));
  EXPECT_THROW(provider.Depth(frame, Camera{}), InputError);
}

TEST(DepthFactoryTest, KnownAndUnknownKinds) {
  FakeSequence with_depth(true);
  DepthFactoryContext context;
  context.sequence = &with_depth;
  EXPECT_EQ(MakeDepthProvider("sensor", context)->Name(), "sensor");
  EXPECT_THROW(MakeDepthProvider("sensor:x", context), InputError);
  EXPECT_THROW(MakeDepthProvider("cache:", context), InputError);
  EXPECT_THROW(MakeDepthProvider("cache:/nonexistent/dir", context), InputError);
  EXPECT_THROW(MakeDepthProvider("lidar", context), InputError);
}

}  // namespace
}  // namespace ademono
