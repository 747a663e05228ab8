#include <algorithm>
#include <exception>
#include <iostream>

#include <spdlog/spdlog.h>

#include "ademono/core/error.h"
#include "ademono/core/memory.h"
#include "command.h"

int main(int argc, char** argv) {
  // Two arenas for a run's threads (tracking, mapping, the prefetch workers): with glibc's
  // default of 8 per core, seq-a's peak RSS grew 27 MB from 1,000 to 3,000 frames, 19 MB more
  // than its heap (docs/performance.md "Memory of long runs"). MALLOC_ARENA_MAX in the
  // environment wins.
  ademono::LimitMallocArenas(2);
  // Large buffers stay in the heap: without it a seq-a run spends 13-15 % of its wall time on
  // page faults (docs/performance.md "Page faults and the tree walk").
  ademono::KeepLargeBuffersInTheHeap(ademono::kMmapThresholdBytes, ademono::kTrimThresholdBytes);
  CLI::App app{
      "ademono: monocular SLAM with metric depth, dynamic-object and distant-point filtering"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "ademono 0.1.0");
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error, off")
      ->capture_default_str()
      // Whatever spdlog reads (it also takes "warning" and "err"); anything else it would
      // silently turn into "off".
      ->check([](const std::string& level) {
        return level == "off" || spdlog::level::from_str(level) != spdlog::level::off
                   ? std::string()
                   : "unknown level '" + level +
                         "' (trace, debug, info, warn, error, critical, off)";
      });

  auto& commands = ademono::cli::Commands();
  std::sort(commands.begin(), commands.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  std::vector<std::pair<CLI::App*, ademono::cli::Runner>> runners;
  for (const auto& command : commands) {
    CLI::App* sub = app.add_subcommand(command.name, command.description);
    runners.emplace_back(sub, command.setup(*sub));
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // Bad arguments are bad input: one line and exit code 2, as every other input error.
    std::cerr << "ademono: error: " << e.what() << " (--help lists the options)\n";
    return 2;
  }
  spdlog::set_level(spdlog::level::from_str(log_level));
  spdlog::set_pattern("[%l] %v");

  for (auto& [sub, runner] : runners) {
    if (!sub->parsed()) continue;
    try {
      return runner();
    } catch (const ademono::InputError& e) {
      std::cerr << "ademono " << sub->get_name() << ": error: " << e.what() << "\n";
      return 2;
    } catch (const std::exception& e) {
      std::cerr << "ademono " << sub->get_name() << ": error: " << e.what() << "\n";
      return 1;
    }
  }
  return 1;
}
