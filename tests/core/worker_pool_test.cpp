#include "ademono/core/worker_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "ademono/core/thread_name.h"

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

TEST(WorkerPoolTest, ItsThreadsCarryThePoolsNameAndIndex) {
  std::set<std::string> names;
  std::mutex names_mutex;
  {
    WorkerPool pool(2, "ademono-test");
    std::vector<std::future<void>> done;
    // Enough tasks that both threads take some (each waits a little).
    for (int i = 0; i < 40; ++i) {
      done.push_back(pool.Submit([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        std::lock_guard<std::mutex> lock(names_mutex);
        names.insert(CurrentThreadName());
      }));
    }
    for (auto& d : done) d.get();
  }
  for (const std::string& name : names)
    EXPECT_TRUE(name == "ademono-test0" || name == "ademono-test1") << name;
  EXPECT_FALSE(names.empty());
}

TEST(ThreadNameTest, ANameLongerThanTheKernelsLimitIsCutNotRefused) {
  std::string seen;
  std::thread([&] {
    SetCurrentThreadName("ademono-a-very-long-thread-name");
    seen = CurrentThreadName();
  }).join();
  EXPECT_EQ(seen, "ademono-a-very-");  // 15 characters
}

}  // namespace
}  // namespace ademono
