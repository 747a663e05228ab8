#include "ademono/core/worker_pool.h"

#include <stdexcept>
#include <string>
#include <utility>

#include "ademono/core/thread_name.h"

namespace ademono {

WorkerPool::WorkerPool(int threads, const std::string& name) {
  if (threads < 1) {
    throw std::invalid_argument("WorkerPool needs at least one thread, got " +
                                std::to_string(threads));
  }
  threads_.reserve(threads);
  for (int i = 0; i < threads; ++i) {
    threads_.emplace_back([this, thread_name = name + std::to_string(i)] {
      SetCurrentThreadName(thread_name);
      Work();
    });
  }
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  ready_.notify_all();
  for (auto& thread : threads_) thread.join();
}

void WorkerPool::Enqueue(std::function<void()> task) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(task));
  }
  ready_.notify_one();
}

void WorkerPool::Work() {
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      ready_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, and nothing left to run
      task = std::move(queue_.front());
      queue_.pop_front();
    }
    task();  // a packaged_task: the task's exception goes to its future
  }
}

}  // namespace ademono
