#pragma once
// Wall-clock milliseconds for the per-stage timings of a run (steady clock: never goes back), and
// the calling thread's own CPU time (what one thread costs, without the time it waits or is
// preempted: the honest per-thread figure on a loaded machine).

#include <time.h>

#include <chrono>

namespace ademono {

using SteadyTime = std::chrono::steady_clock::time_point;

inline SteadyTime Now() { return std::chrono::steady_clock::now(); }

inline double MsSince(SteadyTime start) {
  return std::chrono::duration<double, std::milli>(Now() - start).count();
}

// CPU milliseconds consumed by the calling thread so far (CLOCK_THREAD_CPUTIME_ID).
inline double ThreadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

}  // namespace ademono
