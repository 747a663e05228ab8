#pragma once
// Names the calling thread (Linux: at most 15 characters, longer names are cut), so that
// `top -H`, `perf report --sort comm`, gdb and sanitizer reports tell ademono's threads apart:
// the tracking thread keeps the process's name, the others are "ademono-<role>".

#include <string>

namespace ademono {

void SetCurrentThreadName(const std::string& name);
// The calling thread's name ("" where the platform has none).
std::string CurrentThreadName();

}  // namespace ademono
