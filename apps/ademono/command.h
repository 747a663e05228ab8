#pragma once
// Subcommand registry for the CLI. A cmd_<name>.cpp file registers itself with a static
//   const bool kRegistered = ademono::cli::RegisterCommand("name", "one-line help", Setup);
// where Setup adds options to the CLI11 subcommand and returns the function that runs it.
// Runners return the process exit code; an InputError thrown from a runner is printed as one
// line "ademono <name>: error: <message>" and exits with code 2.

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace ademono::cli {

using Runner = std::function<int()>;
using Setup = std::function<Runner(CLI::App&)>;

struct CommandSpec {
  std::string name;
  std::string description;
  Setup setup;
};

bool RegisterCommand(std::string name, std::string description, Setup setup);
std::vector<CommandSpec>& Commands();

}  // namespace ademono::cli
