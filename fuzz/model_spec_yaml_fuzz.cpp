// Depth model spec YAML (DepthModelSpec::Load), then what a run does with it: the network input
// geometry for two image sizes and the output-to-depth conversion.
#include "ademono/depth/model_spec.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ademono;
  const auto file = fuzz::Scratch() / "spec.yaml";
  fuzz::WriteFile(file, std::string_view(reinterpret_cast<const char*>(data), size));
  fuzz::ExpectOnlyInputError([&] {
    const DepthModelSpec spec = DepthModelSpec::Load(file);
    cv::Size input, content;
    spec.InputGeometry(cv::Size(640, 480), &input, &content);
    spec.InputGeometry(cv::Size(1241, 376), &input, &content);
    fuzz::g_sink = spec.ToDepth(0.5, 1.0) + input.area() + content.area();
  });
  return 0;
}
