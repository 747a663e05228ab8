// Depth cache image loader (ReadDepthMap): 16-bit PNG (mm) or 32-bit float TIFF (m). The input's
// first byte picks the extension OpenCV sees; the rest is the file.
#include "ademono/depth/cache_depth.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ademono;
  if (size == 0) return 0;
  const auto file = fuzz::Scratch() / ((data[0] & 1) ? "depth.tiff" : "depth.png");
  fuzz::WriteFile(file, std::string_view(reinterpret_cast<const char*>(data + 1), size - 1));
  fuzz::ExpectOnlyInputError([&] { ReadDepthMap(file); });
  return 0;
}
