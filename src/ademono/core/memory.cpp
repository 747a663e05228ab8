#include "ademono/core/memory.h"

#include <cstdlib>
#include <cstring>
#include <limits>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace ademono {

bool LimitMallocArenas(int arenas) {
#if defined(__GLIBC__)
  if (arenas < 1 || std::getenv("MALLOC_ARENA_MAX") != nullptr) return false;
  return mallopt(M_ARENA_MAX, arenas) == 1;
#else
  (void)arenas;
  return false;
#endif
}

bool KeepLargeBuffersInTheHeap(size_t mmap_bytes, size_t trim_bytes) {
#if defined(__GLIBC__)
  if (std::getenv("MALLOC_MMAP_THRESHOLD_") != nullptr ||
      std::getenv("MALLOC_TRIM_THRESHOLD_") != nullptr) {
    return false;
  }
  if (const char* tunables = std::getenv("GLIBC_TUNABLES");
      tunables != nullptr && (std::strstr(tunables, "mmap_threshold") != nullptr ||
                              std::strstr(tunables, "trim_threshold") != nullptr)) {
    return false;
  }
  // Both or neither: a fixed mmap threshold alone also fixes the trim threshold at its 128 KB
  // default, which trims the heap top after nearly every free (more faults, not fewer).
  const auto limit = static_cast<size_t>(std::numeric_limits<int>::max());
  if (mmap_bytes == 0 || trim_bytes == 0 || mmap_bytes > limit || trim_bytes > limit) return false;
  return mallopt(M_TRIM_THRESHOLD, static_cast<int>(trim_bytes)) == 1 &&
         mallopt(M_MMAP_THRESHOLD, static_cast<int>(mmap_bytes)) == 1;
#else
  (void)mmap_bytes;
  (void)trim_bytes;
  return false;
#endif
}

bool ReleaseFreedMemory() {
#if defined(__GLIBC__)
  return malloc_trim(0) == 1;
#else
  return false;
#endif
}

}  // namespace ademono
