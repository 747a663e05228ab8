// Detection cache, JSON lines (ReadDetectionsJsonl).
#include "ademono/detect/detection_io.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ademono;
  const auto file = fuzz::Scratch() / "detections.jsonl";
  fuzz::WriteFile(file, std::string_view(reinterpret_cast<const char*>(data), size));
  fuzz::ExpectOnlyInputError([&] { ReadDetectionsJsonl(file); });
  return 0;
}
