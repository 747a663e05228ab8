// Inputs found by fuzzing (fuzz/, docs/reliability.md) that escaped the InputError contract,
// kept so they stay fixed.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "ademono/core/camera.h"
#include "ademono/core/error.h"

namespace ademono {
namespace {

std::string CameraYamlError(const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("ademono_fuzz_regression_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(path, std::ios::binary) << text;
  std::string message;
  try {
    LoadCameraYaml(path);
    ADD_FAILURE() << "expected InputError for: " << text;
  } catch (const InputError& e) {
    message = e.what();
  }
  // Any other exception propagates and fails the test.
  std::filesystem::remove(path);
  return message;
}

TEST(CameraYamlFuzzRegression, ScalarOrListRootIsAMappingError) {
  // fuzz_camera_yaml crash-b98db9eb: the document is one plain scalar; yaml-cpp threw
  // "operator[] call on a scalar" out of LoadCameraYaml (exit 1 instead of 2).
  EXPECT_THAT(CameraYamlError("camera  fx$ 525[0.1, -0.2, 0.001, 0.002, 0.05]\n"),
              testing::HasSubstr("camera YAML must be a mapping"));
  EXPECT_THAT(CameraYamlError("- 1\n- 2\n"), testing::HasSubstr("camera YAML must be a mapping"));
  EXPECT_THAT(CameraYamlError(""), testing::HasSubstr("camera YAML must be a mapping"));
}

TEST(CameraYamlFuzzRegression, ImageSizeMustBeAWholeNumberInRange) {
  const std::string rest = "fx: 1\nfy: 1\ncx: 0\ncy: 0\n";
  for (const char* width : {"1e300", "-5", "0", "2.5", "100001"}) {
    EXPECT_THAT(CameraYamlError(std::string("width: ") + width + "\nheight: 2\n" + rest),
                testing::HasSubstr("camera field 'width' must be a whole number from 1 to 100000"))
        << width;
  }
  EXPECT_THAT(CameraYamlError("width: 2\nheight: 4e9\n" + rest),
              testing::HasSubstr("camera field 'height' must be"));
}

}  // namespace
}  // namespace ademono
