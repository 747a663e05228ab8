// A camera whose principal point lies off its own image is a calibration for other images
// (issue 16: intrinsics that contradict the images); Check() and the YAML reader reject it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "ademono/core/camera.h"
#include "ademono/core/error.h"

namespace ademono {
namespace {

Camera Vga() { return Camera::Pinhole(640, 480, 525, 319.5, 239.5); }

TEST(CameraPrincipalPointTest, InsideOrOnTheBorderIsAccepted) {
  EXPECT_NO_THROW(Vga().Check());
  Camera edge = Vga();
  edge.cx = 0;
  edge.cy = 480;
  EXPECT_NO_THROW(edge.Check());
}

TEST(CameraPrincipalPointTest, OutsideTheImageIsRejected) {
  for (const auto& [cx, cy] : {std::pair{640.5, 239.5}, std::pair{-1.0, 239.5},
                               std::pair{319.5, 481.0}, std::pair{319.5, -0.1}}) {
    Camera c = Vga();
    c.cx = cx;
    c.cy = cy;
    EXPECT_THROW(c.Check(), std::invalid_argument) << cx << ", " << cy;
  }
  // The typical mistake: a 1920x1080 calibration used for 640x480 images.
  Camera full_hd = Vga();
  full_hd.cx = 959.5;
  full_hd.cy = 539.5;
  try {
    full_hd.Check();
    ADD_FAILURE() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "camera principal point (959.5, 539.5) is outside the image (640x480)");
  }
}

TEST(CameraPrincipalPointTest, YamlReaderNamesTheFile) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("ademono_pp_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(path) << "width: 320\nheight: 240\nfx: 262.5\nfy: 262.5\ncx: 639.5\ncy: 119.5\n";
  try {
    LoadCameraYaml(path);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), testing::StartsWith(path.string() + ": "));
    EXPECT_THAT(e.what(), testing::HasSubstr("outside the image (320x240)"));
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace ademono
