#include "ademono/core/memory.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <fstream>
#include <memory>
#include <vector>

// The sanitizers replace malloc: neither malloc_trim nor mallopt reaches glibc's allocator there.
// GCC names them with __SANITIZE_*__, clang with __has_feature.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define ADEMONO_GLIBC_MALLOC 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer)
#define ADEMONO_GLIBC_MALLOC 0
#endif
#endif
#if !defined(ADEMONO_GLIBC_MALLOC) && defined(__GLIBC__)
#define ADEMONO_GLIBC_MALLOC 1
#elif !defined(ADEMONO_GLIBC_MALLOC)
#define ADEMONO_GLIBC_MALLOC 0
#endif

namespace ademono {
namespace {

long ResidentKb() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

TEST(MemoryTest, FreedChunksBetweenLiveOnesGoBackToTheSystem) {
#if !ADEMONO_GLIBC_MALLOC
  GTEST_SKIP() << "glibc's malloc only (the sanitizers bring their own)";
#endif
  // 64 KB chunks (below the mmap threshold: they live in the arena), each followed by a small
  // live one, as a frame's buffers sit between long-lived map data: freeing them cannot shrink
  // the heap from its top, so their pages stay resident until released.
  constexpr int kChunks = 2000;
  constexpr size_t kChunkBytes = 64 * 1024;
  std::vector<std::unique_ptr<char[]>> chunks, pins;
  for (int i = 0; i < kChunks; ++i) {
    chunks.push_back(std::make_unique<char[]>(kChunkBytes));  // zeroed: resident
    pins.push_back(std::make_unique<char[]>(64));
  }
  chunks.clear();
  const long after_free = ResidentKb();
  EXPECT_TRUE(ReleaseFreedMemory());
  const long after_release = ResidentKb();
  // 125 MB freed; at least half of it must leave the resident set.
  EXPECT_LT(after_release, after_free - kChunks * static_cast<long>(kChunkBytes / 1024) / 2)
      << "resident " << after_free << " KB after free, " << after_release << " KB after release";
}

TEST(MemoryTest, TheEnvironmentsArenaLimitIsKept) {
  ASSERT_EQ(setenv("MALLOC_ARENA_MAX", "4", 1), 0);
  EXPECT_FALSE(LimitMallocArenas(2));
  ASSERT_EQ(unsetenv("MALLOC_ARENA_MAX"), 0);
  EXPECT_FALSE(LimitMallocArenas(0));
#if ADEMONO_GLIBC_MALLOC
  EXPECT_TRUE(LimitMallocArenas(2));
#endif
}

long MinorFaults() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

TEST(MemoryTest, LargeBuffersFreedAndAllocatedAgainDoNotFaultTheirPagesIn) {
#if !ADEMONO_GLIBC_MALLOC
  GTEST_SKIP() << "glibc's malloc only (the sanitizers bring their own)";
#endif
  ASSERT_TRUE(KeepLargeBuffersInTheHeap(kMmapThresholdBytes, kTrimThresholdBytes));
  // Buffers that grow from one use to the next, as a local BA's linearisation does with its
  // window: glibc's default maps each one above its (adaptive) threshold afresh and unmaps it
  // when freed, so every page of every buffer faults in again (about 90,000 faults here).
  constexpr int kBuffers = 200;
  const long before = MinorFaults();
  for (int i = 0; i < kBuffers; ++i) {
    const size_t bytes = (size_t{256} << 10) + static_cast<size_t>(i) * (size_t{16} << 10);
    auto buffer = std::make_unique<char[]>(bytes);  // zeroed: every page touched
    ASSERT_EQ(buffer[bytes - 1], 0);
  }
  const long faults = MinorFaults() - before;
  // In the heap, only the pages the largest buffer adds fault in (under 1,000).
  EXPECT_LT(faults, 5000) << faults << " minor page faults for " << kBuffers << " buffers";
}

TEST(MemoryTest, TheEnvironmentsMallocThresholdsAreKept) {
  ASSERT_EQ(setenv("MALLOC_TRIM_THRESHOLD_", "1048576", 1), 0);
  EXPECT_FALSE(KeepLargeBuffersInTheHeap(kMmapThresholdBytes, kTrimThresholdBytes));
  ASSERT_EQ(unsetenv("MALLOC_TRIM_THRESHOLD_"), 0);
  ASSERT_EQ(setenv("GLIBC_TUNABLES", "glibc.malloc.mmap_threshold=1048576", 1), 0);
  EXPECT_FALSE(KeepLargeBuffersInTheHeap(kMmapThresholdBytes, kTrimThresholdBytes));
  ASSERT_EQ(unsetenv("GLIBC_TUNABLES"), 0);
  EXPECT_FALSE(KeepLargeBuffersInTheHeap(0, kTrimThresholdBytes));
}

}  // namespace
}  // namespace ademono
