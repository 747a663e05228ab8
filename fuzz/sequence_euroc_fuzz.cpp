// EuRoC folder: mav0/cam0/data.csv, mav0/cam0/sensor.yaml and the ground truth
// mav0/state_groundtruth_estimate0/data.csv from one input (split at NUL bytes; an empty part
// leaves the file out).
#include "ademono/io/sequence.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ademono;
  const auto parts = fuzz::SplitParts(data, size, 3);
  const auto dir = fuzz::FreshDir("euroc");
  fuzz::WriteFile(dir / "mav0" / "cam0" / "data.csv", parts[0]);
  fuzz::WriteIfAny(dir / "mav0" / "cam0" / "sensor.yaml", parts[1]);
  fuzz::WriteIfAny(dir / "mav0" / "state_groundtruth_estimate0" / "data.csv", parts[2]);
  fuzz::ExpectOnlyInputError([&] { fuzz::TouchSequence(OpenSequence("euroc:" + dir.string())); });
  return 0;
}
