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

// Keeps large buffers in the heap (glibc's M_MMAP_THRESHOLD `mmap_bytes`) and the heap's free top
// resident up to `trim_bytes` (M_TRIM_THRESHOLD). By default glibc maps each chunk of 128 KB or
// more on its own and gives a freed heap top back at once, so every local BA's linearisation
// (2-3 MB, allocated and freed per keyframe) and every frame's image buffers fault their pages
// in again: 150,000-190,000 minor page faults and about 2 s of system time on seq-a, 13-15 % of
// the run's wall time (docs/performance.md "Page faults and the tree walk"). Long runs still
// return freed memory through ReleaseFreedMemory. Process-wide, like LimitMallocArenas, and
// skipped when the environment sets either threshold (MALLOC_MMAP_THRESHOLD_,
// MALLOC_TRIM_THRESHOLD_ or GLIBC_TUNABLES). Returns whether both were applied.
bool KeepLargeBuffersInTheHeap(size_t mmap_bytes, size_t trim_bytes);
inline constexpr size_t kMmapThresholdBytes = size_t{4} << 20;
inline constexpr size_t kTrimThresholdBytes = size_t{32} << 20;

// Hands the pages of freed chunks back to the operating system (glibc's malloc_trim) in every
// arena. Costs a walk of the free lists; the pipeline calls it every
// kReleaseFreedMemoryEveryFrames frames. Returns whether any memory was released.
bool ReleaseFreedMemory();
inline constexpr size_t kReleaseFreedMemoryEveryFrames = 100;

}  // namespace ademono
