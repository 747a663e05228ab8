// 7-Scenes folder (two 64x48 colour frames): frame-000000.pose.txt, frame-000001.pose.txt and
// camera-intrinsics.txt from one input (split at NUL bytes; an empty part leaves the file out).
#include "ademono/io/sequence.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ademono;
  const auto parts = fuzz::SplitParts(data, size, 3);
  const auto dir = fuzz::FreshDir("seq-01");
  fuzz::WriteSmallImage(dir / "frame-000000.color.png", 3);
  fuzz::WriteSmallImage(dir / "frame-000001.color.png", 3);
  fuzz::WriteIfAny(dir / "frame-000000.pose.txt", parts[0]);
  fuzz::WriteIfAny(dir / "frame-000001.pose.txt", parts[1]);
  fuzz::WriteIfAny(dir / "camera-intrinsics.txt", parts[2]);
  fuzz::ExpectOnlyInputError(
      [&] { fuzz::TouchSequence(OpenSequence("7scenes:" + dir.string())); });
  return 0;
}
