// Euroc trajectory reader (ReadTrajectory(path, kEuroc)).
#include "ademono/io/trajectory.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ademono;
  const auto file = fuzz::Scratch() / "trajectory.txt";
  fuzz::WriteFile(file, std::string_view(reinterpret_cast<const char*>(data), size));
  fuzz::ExpectOnlyInputError([&] { ReadTrajectory(file, TrajectoryFormat::kEuroc); });
  return 0;
}
