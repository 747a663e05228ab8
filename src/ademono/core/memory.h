#pragma once
// Keeping a long run's resident memory to what it uses. glibc's malloc gives each thread that
// allocates under contention an arena of its own (up to 8 per core) and returns a freed chunk
// only to its arena, where frames' image buffers, allocated on prefetch threads and freed on
// the tracking thread, leave holes between long-lived map data. On seq-a played for 3,000
// frames with FastDepth the peak RSS grew 27 MB beyond the 1,000-frame run's while the heap
// itself grew 8.5 MB (heaptrack; tools/soak_fastdepth.sh). Elsewhere both are no-ops.

#include <cstddef>

namespace ademono {

// Caps the number of malloc arenas (glibc's M_ARENA_MAX) unless the environment already sets
// MALLOC_ARENA_MAX. Process-wide: executables call it first thing, before any thread starts;
// a library embedding ademono leaves it to its host. Returns whether the cap was applied.
bool LimitMallocArenas(int arenas);

// Hands the pages of freed chunks back to the operating system (glibc's malloc_trim) in every
// arena. Costs a walk of the free lists; the pipeline calls it every
// kReleaseFreedMemoryEveryFrames frames. Returns whether any memory was released.
bool ReleaseFreedMemory();
inline constexpr size_t kReleaseFreedMemoryEveryFrames = 100;

}  // namespace ademono
