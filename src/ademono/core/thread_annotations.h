#pragma once
// Clang thread-safety annotations (https://clang.llvm.org/docs/ThreadSafetyAnalysis.html) and a
// mutex that carries them. They make a lock contract checkable at compile time:
// `tools/thread_safety.sh` compiles the slam module with clang -Wthread-safety -Werror. Under GCC
// (the release build) the macros expand to nothing and Mutex is a plain std::mutex.
//
//   Mutex mutex;
//   int value ADEMONO_GUARDED_BY(mutex);
//   void Edit() ADEMONO_REQUIRES(mutex);         // the caller holds `mutex`
//   { MutexLock lock(mutex); Edit(); }           // a scoped lock the analysis understands

#include <atomic>
#include <mutex>
#include <stdexcept>
#include <thread>

#if defined(__clang__)
#define ADEMONO_THREAD_ANNOTATION(x) __attribute__((x))
#else
#define ADEMONO_THREAD_ANNOTATION(x)
#endif

#define ADEMONO_CAPABILITY(x) ADEMONO_THREAD_ANNOTATION(capability(x))
#define ADEMONO_SCOPED_CAPABILITY ADEMONO_THREAD_ANNOTATION(scoped_lockable)
#define ADEMONO_GUARDED_BY(x) ADEMONO_THREAD_ANNOTATION(guarded_by(x))
#define ADEMONO_PT_GUARDED_BY(x) ADEMONO_THREAD_ANNOTATION(pt_guarded_by(x))
#define ADEMONO_REQUIRES(...) ADEMONO_THREAD_ANNOTATION(requires_capability(__VA_ARGS__))
#define ADEMONO_EXCLUDES(...) ADEMONO_THREAD_ANNOTATION(locks_excluded(__VA_ARGS__))
#define ADEMONO_ACQUIRE(...) ADEMONO_THREAD_ANNOTATION(acquire_capability(__VA_ARGS__))
#define ADEMONO_RELEASE(...) ADEMONO_THREAD_ANNOTATION(release_capability(__VA_ARGS__))
#define ADEMONO_TRY_ACQUIRE(...) ADEMONO_THREAD_ANNOTATION(try_acquire_capability(__VA_ARGS__))
#define ADEMONO_ASSERT_CAPABILITY(x) ADEMONO_THREAD_ANNOTATION(assert_capability(x))
#define ADEMONO_RETURN_CAPABILITY(x) ADEMONO_THREAD_ANNOTATION(lock_returned(x))
#define ADEMONO_NO_THREAD_SAFETY_ANALYSIS ADEMONO_THREAD_ANNOTATION(no_thread_safety_analysis)

namespace ademono {

// std::mutex as a capability (libstdc++'s std::mutex carries no annotations). BasicLockable, so
// std::unique_lock and std::condition_variable_any still work with it, unchecked.
// It remembers its owner, so that AssertHeld is checked at run time too.
class ADEMONO_CAPABILITY("mutex") Mutex {
 public:
  void lock() ADEMONO_ACQUIRE() {
    mutex_.lock();
    owner_.store(std::this_thread::get_id(), std::memory_order_relaxed);
  }
  void unlock() ADEMONO_RELEASE() {
    owner_.store(std::thread::id(), std::memory_order_relaxed);
    mutex_.unlock();
  }
  bool try_lock() ADEMONO_TRY_ACQUIRE(true) {
    if (!mutex_.try_lock()) return false;
    owner_.store(std::this_thread::get_id(), std::memory_order_relaxed);
    return true;
  }
  // Tells the analysis that the calling thread holds this mutex where it cannot see it (a
  // function reached through another object's reference to the same mutex), and checks it: a
  // caller that does not hold it is a bug (std::logic_error).
  void AssertHeld() const ADEMONO_ASSERT_CAPABILITY(this) {
    if (owner_.load(std::memory_order_relaxed) != std::this_thread::get_id())
      throw std::logic_error("ademono::Mutex::AssertHeld: the calling thread does not hold it");
  }

 private:
  std::mutex mutex_;
  std::atomic<std::thread::id> owner_{};
};

// std::lock_guard for Mutex, visible to the analysis.
class ADEMONO_SCOPED_CAPABILITY MutexLock {
 public:
  explicit MutexLock(Mutex& mutex) ADEMONO_ACQUIRE(mutex) : mutex_(mutex) { mutex_.lock(); }
  ~MutexLock() ADEMONO_RELEASE() { mutex_.unlock(); }
  MutexLock(const MutexLock&) = delete;
  MutexLock& operator=(const MutexLock&) = delete;

 private:
  Mutex& mutex_;
};

}  // namespace ademono
