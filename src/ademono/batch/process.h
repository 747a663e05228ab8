#pragma once
// Child processes for the batch engines: a task's command with its output in its log, and the
// Slurm client commands (sbatch, squeue) with their output captured.

#include <sys/types.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace ademono::batch {

// Starts argv[0] (a path) with stdin from /dev/null and stdout and stderr into `log` (created or
// truncated). Returns the child's pid; std::runtime_error when it cannot start.
pid_t SpawnLogged(const std::vector<std::string>& argv, const std::filesystem::path& log);

struct CommandResult {
  int exit_code = -1;  // 128 + signal when killed
  std::string output;  // stdout and stderr
};
// Runs argv (argv[0] looked up on PATH) to its end and captures what it prints.
CommandResult RunCommand(const std::vector<std::string>& argv);

// The program's path on PATH, if it is there and executable.
std::optional<std::filesystem::path> FindOnPath(const std::string& program);

// Exit code of a waitpid status: the code, or 128 + signal.
int ExitCode(int status);

}  // namespace ademono::batch
