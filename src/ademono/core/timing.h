#pragma once
// Wall-clock milliseconds for the per-stage timings of a run (steady clock: never goes back).

#include <chrono>

namespace ademono {

using SteadyTime = std::chrono::steady_clock::time_point;

inline SteadyTime Now() { return std::chrono::steady_clock::now(); }

inline double MsSince(SteadyTime start) {
  return std::chrono::duration<double, std::milli>(Now() - start).count();
}

}  // namespace ademono
