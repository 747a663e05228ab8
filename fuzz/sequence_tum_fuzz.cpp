// TUM RGB-D folder: rgb.txt, depth.txt, groundtruth.txt and camera.yaml from one input (split at
// NUL bytes; an empty part leaves the file out).
#include "ademono/io/sequence.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ademono;
  const auto parts = fuzz::SplitParts(data, size, 4);
  // The folder name selects the freiburg1 Kinect when there is no camera.yaml.
  const auto dir = fuzz::FreshDir("rgbd_dataset_freiburg1_fuzz");
  fuzz::WriteFile(dir / "rgb.txt", parts[0]);
  fuzz::WriteIfAny(dir / "depth.txt", parts[1]);
  fuzz::WriteIfAny(dir / "groundtruth.txt", parts[2]);
  fuzz::WriteIfAny(dir / "camera.yaml", parts[3]);
  fuzz::ExpectOnlyInputError([&] { fuzz::TouchSequence(OpenSequence("tum:" + dir.string())); });
  return 0;
}
