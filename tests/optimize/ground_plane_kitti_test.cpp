// The ground plane on real KITTI frames (../shared/data/kitti-00, every 10th of its 200) with
// PyDNet's depth (../shared/models/pydnet_kitti.onnx, configs/models/pydnet_kitti.yaml):
// the measurements behind docs/kitti.md, as assertions. 20 PyDNet runs: 4 s at 208 ms a frame,
// 12-25 s on the loaded machine they were measured on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <vector>

#include "ademono/core/statistics.h"
#include "ademono/depth/onnx_depth.h"
#include "ademono/io/sequence.h"
#include "ademono/optimize/ground_plane.h"

namespace ademono {
namespace {

namespace fs = std::filesystem;

struct FrameFit {
  GroundPlane network;    // a plane through PyDNet's depth where tracking fitted it
  GroundPlane level;      // PyDNet's near road along the camera's up axis
  GroundPlane two_view;   // the road's homography to frame + 2 under the ground-truth motion
};

class GroundPlaneKittiTest : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    const fs::path shared = ADEMONO_SHARED_DIR;
    const auto sequence = OpenSequence("kitti:" + (shared / "data/kitti-00/sequences/00").string());
    OnnxDepthProvider pydnet(shared / "models/pydnet_kitti.onnx",
                             fs::path(ADEMONO_SOURCE_DIR) / "configs/models/pydnet_kitti.yaml",
                             OrtSessionOptions{});
    const Camera& camera = sequence->GetCamera();
    // Tracking's corridor (depth.ground_max_lateral 4 m, ground_max_depth 25 m, 15 degrees).
    GroundFromDepthOptions tracking;
    tracking.min_depth = 0;
    tracking.max_depth = 25;
    tracking.max_lateral = 4;
    fits_ = std::make_unique<std::vector<FrameFit>>();
    for (size_t i = 0; i + 2 < sequence->Size(); i += 10) {
      const FrameData a = sequence->Load(i);
      const FrameData b = sequence->Load(i + 2);
      const cv::Mat depth = pydnet.Depth(a, camera);
      FrameFit fit;
      fit.network = EstimateGroundFromDepth(depth, camera, {}, tracking);
      fit.level = GroundHeightAlong(RoadCandidates(depth, camera, {}, GroundFromDepthOptions{}),
                                    Eigen::Vector3d(0, -1, 0));
      const Rigid3d b_from_a = b.world_from_cam_gt->inverse() * *a.world_from_cam_gt;
      fit.two_view = EstimateGroundFromTwoViews(a.image, b.image, b_from_a, camera, fit.level);
      fits_->push_back(fit);
    }
  }
  static void TearDownTestSuite() {
    fits_.reset();
  }
  // The valid estimates' heights (or every one that has a height: `any`).
  static std::vector<double> Heights(GroundPlane FrameFit::*which, bool any = false) {
    std::vector<double> h;
    for (const FrameFit& f : *fits_) {
      if ((f.*which).valid || (any && (f.*which).height > 0)) h.push_back((f.*which).height);
    }
    return h;
  }
  // Share of all frames whose height is within `fraction` of `median`.
  static double ShareWithin(const std::vector<double>& heights, double median, double fraction) {
    const auto n = std::count_if(heights.begin(), heights.end(), [&](double h) {
      return std::abs(h / median - 1.0) <= fraction;
    });
    return static_cast<double>(n) / static_cast<double>(fits_->size());
  }
  static inline std::unique_ptr<std::vector<FrameFit>> fits_;
};

TEST_F(GroundPlaneKittiTest, APlaneThroughPyDNetsDepthTiltsUpAndReadsTheCameraTooHigh) {
  // Why depth.camera_height made KITTI worse: PyDNet reads the road 1.04x short at 5-10 m but
  // 1.5-2.3x short beyond (tools/kitti_depth_eval.py), so its road rises ahead: the plane
  // tilts up by several degrees and meets the camera's vertical far below the real road.
  std::vector<double> pitch;
  for (const FrameFit& f : *fits_) {
    if (f.network.valid) pitch.push_back(std::atan2(f.network.normal.z(), -f.network.normal.y()));
  }
  ASSERT_GE(pitch.size(), 10u);
  EXPECT_LT(Median(pitch) * 180 / M_PI, -3.0);  // measured -5.6 degrees
  const std::vector<double> h = Heights(&FrameFit::network);
  EXPECT_GT(Median(h), 1.15 * 1.65);             // measured 2.04 m
  EXPECT_LT(ShareWithin(h, Median(h), 0.03), 0.3);  // measured 0.15
}

TEST_F(GroundPlaneKittiTest, PyDNetsNearRoadAlongTheUpAxisIsShortAndNoisy) {
  // Mostly not `valid`: under half of the corridor lies within 5 % of one height.
  const std::vector<double> h = Heights(&FrameFit::level, /*any=*/true);
  ASSERT_EQ(h.size(), fits_->size());
  // 5-15 % low at the median (the network reads the near road about 8 % short, and the
  // corridor reaches 20 m where it reads shorter still); +-7 % from frame to frame.
  EXPECT_GT(Median(h), 0.8 * 1.65);
  EXPECT_LT(Median(h), 0.95 * 1.65);
}

TEST_F(GroundPlaneKittiTest, TwoViewsOfTheRoadGiveTheRigsHeight) {
  const std::vector<double> h = Heights(&FrameFit::two_view);
  ASSERT_GE(h.size(), 17u);  // measured 18 of 20
  const double median = Median(h);
  EXPECT_NEAR(median, 1.65, 0.03 * 1.65);  // measured 1.676 m
  // Per frame it scatters (ground truth's relative poses over 1.4 m, pitch and height fitted
  // together): measured 45 % of the frames within 3 % of the median, 75 % within 10 %.
  EXPECT_GE(ShareWithin(h, median, 0.10), 0.65);
  EXPECT_GE(ShareWithin(h, median, 0.03), 0.35);
}

}  // namespace
}  // namespace ademono
