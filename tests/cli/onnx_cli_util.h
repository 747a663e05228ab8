#pragma once
// Helpers for the detect/depth/infer CLI tests: run the built `ademono`, capture its output.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace ademono::onnx_cli_test {

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

inline std::filesystem::path FreshTempDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("ademono_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace ademono::onnx_cli_test
