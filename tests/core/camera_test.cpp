#include "ademono/core/camera.h"

#include <unistd.h>
#include <string>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "ademono/core/error.h"

namespace ademono {
namespace {

Camera DistortedCamera() {
  Camera c;
  c.width = 640;
  c.height = 480;
  c.fx = 520.9;
  c.fy = 521.0;
  c.cx = 325.1;
  c.cy = 249.7;
  c.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};  // TUM fr1
  return c;
}

TEST(Camera, ProjectUnprojectRoundTrip) {
  Camera c = DistortedCamera();
  c.distortion = {0, 0, 0, 0, 0};
  const Eigen::Vector3d p(0.3, -0.2, 2.5);
  const Eigen::Vector2d px = c.Project(p);
  EXPECT_NEAR(px.x(), 520.9 * 0.3 / 2.5 + 325.1, 1e-12);
  const Eigen::Vector3d back = c.Unproject(px, 2.5);
  EXPECT_NEAR((back - p).norm(), 0.0, 1e-12);
}

TEST(Camera, UndistortInvertsDistort) {
  const Camera c = DistortedCamera();
  for (double u : {10.0, 200.0, 325.0, 600.0})
    for (double v : {15.0, 240.0, 470.0}) {
      const Eigen::Vector2d undistorted(u, v);
      const Eigen::Vector2d distorted = c.Distort(undistorted);
      EXPECT_NEAR((c.Undistort(distorted) - undistorted).norm(), 0.0, 1e-3) << u << "," << v;
    }
}

TEST(Camera, LoadYamlAndMissingField) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("ademono_camera_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto good = dir / "good.yaml";
  std::ofstream(good) << "camera:\n  width: 640\n  height: 480\n  fx: 500\n  fy: 501\n  cx: 320\n"
                         "  cy: 240\n  distortion: [0.1, -0.2, 0.0, 0.0]\n";
  const Camera c = LoadCameraYaml(good);
  EXPECT_EQ(c.width, 640);
  EXPECT_DOUBLE_EQ(c.fy, 501);
  EXPECT_DOUBLE_EQ(c.distortion[1], -0.2);
  EXPECT_DOUBLE_EQ(c.distortion[4], 0.0);

  const auto bad = dir / "bad.yaml";
  std::ofstream(bad) << "width: 640\nheight: 480\nfx: 500\nfy: 500\ncx: 320\n";
  try {
    LoadCameraYaml(bad);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("bad.yaml"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'cy' is missing"), std::string::npos) << msg;
  }
  EXPECT_THROW(LoadCameraYaml(dir / "nope.yaml"), InputError);
}

TEST(Camera, ScaledKeepsPixelCentres) {
  Camera c = DistortedCamera();
  const Camera half = c.Scaled(0.5, 0.5);
  EXPECT_EQ(half.width, 320);
  EXPECT_NEAR(half.cx, (325.1 + 0.5) * 0.5 - 0.5, 1e-12);
}

}  // namespace
}  // namespace ademono
