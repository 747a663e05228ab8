#pragma once
// SIGINT and SIGTERM go to `handler` while this lives; the previous handlers come back after.
// `flags`: sigaction's (SA_RESETHAND lets a second signal end the process at once; 0 without
// SA_RESTART makes waitpid return to look at a flag).

#include <csignal>

namespace ademono::cli {

class StopSignals {
 public:
  StopSignals(void (*handler)(int), int flags) {
    struct sigaction action {};
    action.sa_handler = handler;
    sigemptyset(&action.sa_mask);
    action.sa_flags = flags;
    sigaction(SIGINT, &action, &old_int_);
    sigaction(SIGTERM, &action, &old_term_);
  }
  ~StopSignals() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

}  // namespace ademono::cli
