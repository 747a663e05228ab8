#include "ademono/depth/simulated_depth.h"

#include <unistd.h>
#include <string>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "ademono/core/error.h"
#include "ademono/depth/depth_factory.h"

namespace ademono {
namespace {

namespace fs = std::filesystem;

SimulatedDepthOptions Quiet() {
  SimulatedDepthOptions options;
  options.scale = 1.0, options.a = 0.0, options.b = 0.0, options.edge_blur = 0;
  options.invalid = 0.0;
  return options;
}

cv::Mat Constant(double z) { return cv::Mat(300, 400, CV_32F, cv::Scalar(z)); }

// Mean ratio is the scale bias; the error spread follows sigma = a z + b z^2 at every depth.
TEST(SimulatedDepth, ScaleBiasAndErrorGrowWithDepthAsConfigured) {
  SimulatedDepthOptions options;
  options.scale = 1.05, options.a = 0.01, options.b = 0.002, options.edge_blur = 0;
  options.invalid = 0.0, options.seed = 9;
  const SimulatedDepthProvider provider(options, nullptr);
  std::vector<double> spreads;
  for (double z : {2.0, 10.0, 30.0}) {
    double ratio_sum = 0.0, spread_sum = 0.0;
    const int frames = 4;
    for (int f = 0; f < frames; ++f) {
      const cv::Mat out = provider.Degrade(Constant(z), f);
      cv::Scalar mean, stddev;
      cv::meanStdDev(out, mean, stddev);
      ratio_sum += mean[0] / z;
      spread_sum += stddev[0] / options.scale;
    }
    const double sigma = options.a * z + options.b * z * z;
    EXPECT_NEAR(ratio_sum / frames, 1.05, 0.002) << "z " << z;
    EXPECT_NEAR(spread_sum / frames, sigma, 0.05 * sigma) << "z " << z;
    spreads.push_back(spread_sum / frames);
  }
  EXPECT_GT(spreads[1], 3 * spreads[0]);
  EXPECT_GT(spreads[2], 3 * spreads[1]);
}

TEST(SimulatedDepth, ErrorsAreSpatiallyCorrelated) {
  SimulatedDepthOptions options = Quiet();
  options.a = 0.05;
  const SimulatedDepthProvider provider(options, nullptr);
  const cv::Mat error = provider.Degrade(Constant(4.0), 0) - 4.0;
  cv::Mat left = error(cv::Rect(0, 0, 399, 300)), right = error(cv::Rect(1, 0, 399, 300));
  cv::Scalar ml, sl, mr, sr;
  cv::meanStdDev(left, ml, sl);
  cv::meanStdDev(right, mr, sr);
  const double covariance = cv::mean((left - ml[0]).mul(right - mr[0]))[0];
  const double correlation = covariance / (sl[0] * sr[0]);
  EXPECT_GT(correlation, 0.8);   // 90 % of the variance is a smooth field
  EXPECT_LT(correlation, 0.95);  // and 10 % per-pixel noise
  // All per-pixel: no correlation.
  options.pixel = 1.0;
  const SimulatedDepthProvider white(options, nullptr);
  const cv::Mat white_error = white.Degrade(Constant(4.0), 0) - 4.0;
  const double white_correlation =
      cv::mean(
          white_error(cv::Rect(0, 0, 399, 300)).mul(white_error(cv::Rect(1, 0, 399, 300))))[0] /
      cv::mean(white_error.mul(white_error))[0];
  EXPECT_LT(std::abs(white_correlation), 0.02);
}

TEST(SimulatedDepth, InvalidFractionInBlobsAndMissingTruthStaysInvalid) {
  SimulatedDepthOptions options = Quiet();
  options.invalid = 0.1;
  const SimulatedDepthProvider provider(options, nullptr);
  const cv::Mat full = provider.Degrade(Constant(3.0), 3);
  const cv::Mat invalid = full == 0.f;
  EXPECT_NEAR(cv::countNonZero(invalid) / 120000.0, 0.1, 0.001);
  // Blobs: most right-hand neighbours of an invalid pixel are invalid too (salt noise: 10 %).
  const cv::Mat both = invalid(cv::Rect(0, 0, 399, 300)) & invalid(cv::Rect(1, 0, 399, 300));
  EXPECT_GT(cv::countNonZero(both), 0.8 * cv::countNonZero(invalid(cv::Rect(0, 0, 399, 300))));

  cv::Mat truth = Constant(3.0);
  truth(cv::Rect(0, 0, 100, 300)).setTo(0.f);
  truth.at<float>(5, 200) = std::nanf("");
  const cv::Mat out = provider.Degrade(truth, 3);
  EXPECT_EQ(cv::countNonZero(out(cv::Rect(0, 0, 100, 300))), 0);
  EXPECT_EQ(out.at<float>(5, 200), 0.f);
}

TEST(SimulatedDepth, EdgesAreSmearedOnlyNearDiscontinuities) {
  SimulatedDepthOptions options = Quiet();
  options.edge_blur = 3;
  const SimulatedDepthProvider provider(options, nullptr);
  cv::Mat truth = Constant(2.0);
  truth(cv::Rect(200, 0, 200, 300)).setTo(6.f);
  const cv::Mat out = provider.Degrade(truth, 0);
  for (int u = 0; u < 400; ++u) {
    const float z = out.at<float>(150, u);
    if (u < 197) {
      EXPECT_FLOAT_EQ(z, 2.f) << u;
    } else if (u >= 203) {
      EXPECT_FLOAT_EQ(z, 6.f) << u;
    } else {
      EXPECT_GT(z, 2.f) << u;
      EXPECT_LT(z, 6.f) << u;
    }
  }
}

TEST(SimulatedDepth, DeterministicPerSeedAndFrame) {
  SimulatedDepthOptions options;
  options.seed = 5;
  const SimulatedDepthProvider a(options, nullptr), b(options, nullptr);
  options.seed = 6;
  const SimulatedDepthProvider c(options, nullptr);
  const cv::Mat truth = Constant(5.0);
  EXPECT_EQ(cv::norm(a.Degrade(truth, 7), b.Degrade(truth, 7), cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a.Degrade(truth, 7), a.Degrade(truth, 8), cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a.Degrade(truth, 7), c.Degrade(truth, 7), cv::NORM_INF), 0.0);
}

TEST(SimulatedDepth, FactorySpecAndErrors) {
  DepthFactoryContext context;
  context.seed = 3;
  auto provider =
      MakeDepthProvider("simulated:scale=1.2,a=0,b=0,edge_blur=0,invalid=0,seed=4", context);
  EXPECT_EQ(provider->Name(), "simulated");
  FrameData frame;
  frame.name = "f0";
  frame.depth = Constant(2.5);
  Camera camera;
  const cv::Mat out = provider->Depth(frame, camera);
  EXPECT_NEAR(cv::norm(out - 3.0, cv::NORM_INF), 0.0, 1e-5);
  EXPECT_NO_THROW(MakeDepthProvider("simulated", context));

  auto message = [&](const std::string& spec) -> std::string {
    try {
      MakeDepthProvider(spec, context);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(message("simulated:foo=1"),
            "depth provider 'simulated': unknown parameter 'foo' (expected scale, a, b, pixel, "
            "edge_blur, invalid, jitter, jitter_frames, shift, shift_jitter, seed, gt)");
  EXPECT_EQ(message("simulated:scale=abc"),
            "depth provider 'simulated': 'scale=abc' is not a number");
  EXPECT_EQ(message("simulated:invalid=1.5"),
            "depth provider 'simulated': invalid must be in [0, 1)");
  EXPECT_EQ(message("simulated:edge_blur=2.5"),
            "depth provider 'simulated': 'edge_blur=2.5' must be a non-negative integer");
  EXPECT_EQ(message("simulated:pixel=2"), "depth provider 'simulated': pixel must be in [0, 1]");
  EXPECT_EQ(message("simulated:scale"), "depth provider 'simulated': 'scale' is not key=value");

  FrameData no_depth;
  no_depth.name = "frame-7";
  auto plain = MakeDepthProvider("simulated", context);
  try {
    plain->Depth(no_depth, camera);
    FAIL() << "no error for a frame without depth";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame 'frame-7' has no ground-truth depth"),
              std::string::npos);
  }
}

TEST(SimulatedDepth, GroundTruthFromCacheFolder) {
  const fs::path dir =
      fs::temp_directory_path() / ("ademono_simulated_gt_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  cv::imwrite((dir / "0.100000.tiff").string(), Constant(40.0));
  DepthFactoryContext context;
  auto provider = MakeDepthProvider(
      "simulated:gt=" + dir.string() + ",scale=1,a=0,b=0,edge_blur=0,invalid=0", context);
  FrameData frame;
  frame.name = "0.100000";
  frame.timestamp = 0.1;
  frame.image = cv::Mat(300, 400, CV_8UC3, cv::Scalar(0, 0, 0));
  frame.depth = Constant(0.0);  // the dataset's own depth is ignored
  Camera camera;
  camera.width = 400, camera.height = 300, camera.fx = camera.fy = 300;
  const cv::Mat out = provider->Depth(frame, camera);
  EXPECT_NEAR(cv::norm(out - 40.0, cv::NORM_INF), 0.0, 1e-4);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ademono
