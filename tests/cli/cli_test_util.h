#pragma once
// Helpers for the CLI tests: run the built `ademono` (ADEMONO_CLI) and capture what it prints.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace ademono::cli_test {

struct CliResult {
  int code = -1;
  std::string out;  // stdout and stderr
};

inline CliResult RunCli(const std::string& args) {
  CliResult result;
  const std::string command = std::string(ADEMONO_CLI) + " " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  std::array<char, 4096> buffer;
  while (fgets(buffer.data(), buffer.size(), pipe) != nullptr) result.out += buffer.data();
  const int status = pclose(pipe);
  result.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

struct CliRun {
  int exit_code = -1;
  std::string out, err;  // stdout and stderr, captured separately
};

inline std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs a shell command (a tool of tools/, say) with stdout and stderr captured through files in
// `scratch_dir`.
inline CliRun RunCommand(const std::string& command, const std::filesystem::path& scratch_dir) {
  const auto out = scratch_dir / "stdout.txt", err = scratch_dir / "stderr.txt";
  const int status = std::system((command + " >" + out.string() + " 2>" + err.string()).c_str());
  CliRun result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = ReadFile(out);
  result.err = ReadFile(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return result;
}

// Runs `ademono ARGS` with stdout and stderr captured through files in `scratch_dir`.
inline CliRun RunAdemono(const std::string& args, const std::filesystem::path& scratch_dir) {
  return RunCommand(std::string(ADEMONO_CLI) + " " + args, scratch_dir);
}

inline std::filesystem::path FreshTempDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("ademono_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace ademono::cli_test
