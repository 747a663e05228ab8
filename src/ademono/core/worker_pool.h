#pragma once
// A fixed set of threads that run submitted tasks in submission order. The pipeline prepares
// frames on one instead of a thread per task: OpenCV 4.6 keeps per-thread state (its TLS, first
// touched by cv::cvtColor's parallel_for_) that it never frees when a thread exits, 0.8 KB for
// every thread that extracted a frame (heaptrack on seq-a for 3,000 frames: 2.4 MB leaked,
// growing with the run; docs/performance.md "Memory of long runs"). A task must not wait for
// another task of the same pool (with every thread waiting, the awaited one would never start).

#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

namespace ademono {

class WorkerPool {
 public:
  // Its threads are named `name` and their index ("ademono-prep0", ...: thread_name.h).
  explicit WorkerPool(int threads, const std::string& name = "ademono-pool");
  // Runs the tasks still queued, then joins the threads.
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int Size() const { return static_cast<int>(threads_.size()); }

  // The task's result or exception arrives through the future, as with std::async.
  template <class F>
  std::future<std::invoke_result_t<F>> Submit(F&& task) {
    using Result = std::invoke_result_t<F>;
    auto packaged = std::make_shared<std::packaged_task<Result()>>(std::forward<F>(task));
    std::future<Result> result = packaged->get_future();
    Enqueue([packaged] { (*packaged)(); });
    return result;
  }

 private:
  void Enqueue(std::function<void()> task);
  void Work();

  std::mutex mutex_;  // a std::mutex for the condition variable: not annotated
  std::condition_variable ready_;
  std::deque<std::function<void()>> queue_;  // guarded by mutex_
  bool stop_ = false;                        // guarded by mutex_
  std::vector<std::thread> threads_;
};

}  // namespace ademono
