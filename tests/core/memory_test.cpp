#include "ademono/core/memory.h"

#include <gtest/gtest.h>
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

}  // namespace
}  // namespace ademono
