#include "command.h"

namespace ademono::cli {

std::vector<CommandSpec>& Commands() {
  static std::vector<CommandSpec> commands;
  return commands;
}

bool RegisterCommand(std::string name, std::string description, Setup setup) {
  Commands().push_back({std::move(name), std::move(description), std::move(setup)});
  return true;
}

}  // namespace ademono::cli
