#include "ademono/core/thread_name.h"

#include <pthread.h>

namespace ademono {

namespace {
constexpr size_t kMaxNameLength = 15;  // the kernel's 16 bytes with the terminating zero
}  // namespace

void SetCurrentThreadName(const std::string& name) {
  // Only a diagnostic: a failure leaves the inherited name.
  (void)pthread_setname_np(pthread_self(), name.substr(0, kMaxNameLength).c_str());
}

std::string CurrentThreadName() {
  char name[kMaxNameLength + 1] = {};
  if (pthread_getname_np(pthread_self(), name, sizeof(name)) != 0) return "";
  return name;
}

}  // namespace ademono
