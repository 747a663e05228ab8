#include "ademono/core/worker_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace ademono {
namespace {

TEST(WorkerPoolTest, RunsEveryTaskOnItsOwnFixedThreads) {
  std::set<std::thread::id> ids;
  std::mutex ids_mutex;
  {
    WorkerPool pool(2);
    EXPECT_EQ(pool.Size(), 2);
    std::vector<std::future<int>> results;
    for (int i = 0; i < 200; ++i) {
      results.push_back(pool.Submit([i, &ids, &ids_mutex] {
        std::lock_guard<std::mutex> lock(ids_mutex);
        ids.insert(std::this_thread::get_id());
        return i * i;
      }));
    }
    for (int i = 0; i < 200; ++i) EXPECT_EQ(results[i].get(), i * i);
  }
  // 200 tasks, at most two threads: a thread per task is what leaked OpenCV's TLS.
  EXPECT_GE(ids.size(), 1u);
  EXPECT_LE(ids.size(), 2u);
  EXPECT_EQ(ids.count(std::this_thread::get_id()), 0u);
}

TEST(WorkerPoolTest, ATasksExceptionReachesItsFuture) {
  WorkerPool pool(1);
  auto failed = pool.Submit([]() -> int { throw std::runtime_error("bad frame"); });
  auto fine = pool.Submit([] { return 7; });
  EXPECT_THROW(failed.get(), std::runtime_error);
  EXPECT_EQ(fine.get(), 7);  // the thread survived the exception
}

TEST(WorkerPoolTest, TheDestructorRunsWhatIsQueued) {
  std::atomic<int> ran{0};
  {
    WorkerPool pool(1);
    for (int i = 0; i < 50; ++i) pool.Submit([&ran] { ++ran; });
  }
  EXPECT_EQ(ran.load(), 50);
  EXPECT_THROW(WorkerPool(0), std::invalid_argument);
}

}  // namespace
}  // namespace ademono
