// KITTI odometry folder (two 64x48 images): calib.txt, times.txt and poses/00.txt from one input
// (split at NUL bytes; an empty part leaves the file out).
#include "ademono/io/sequence.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ademono;
  const auto parts = fuzz::SplitParts(data, size, 3);
  const auto dir = fuzz::FreshDir("00");
  fuzz::WriteSmallImage(dir / "image_0" / "000000.png", 1);
  fuzz::WriteSmallImage(dir / "image_0" / "000001.png", 1);
  fuzz::WriteFile(dir / "calib.txt", parts[0]);
  fuzz::WriteIfAny(dir / "times.txt", parts[1]);
  fuzz::WriteIfAny(dir / "poses" / "00.txt", parts[2]);
  fuzz::ExpectOnlyInputError([&] { fuzz::TouchSequence(OpenSequence("kitti:" + dir.string())); });
  return 0;
}
