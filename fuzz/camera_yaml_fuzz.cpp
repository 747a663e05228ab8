// Camera YAML (LoadCameraYaml), then the camera in use: project and undistort a few pixels.
#include "ademono/core/camera.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ademono;
  const auto file = fuzz::Scratch() / "camera.yaml";
  fuzz::WriteFile(file, std::string_view(reinterpret_cast<const char*>(data), size));
  fuzz::ExpectOnlyInputError([&] {
    const Camera camera = LoadCameraYaml(file);
    const Eigen::Vector2d corner(camera.width - 1.0, camera.height - 1.0);
    fuzz::g_sink = camera.Undistort(corner).x() + camera.Unproject(corner, 1.0).z();
  });
  return 0;
}
