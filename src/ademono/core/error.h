#pragma once
// Errors for bad user input. Every message is one line that names the file (and line) and the
// problem, so the CLI can print it as is and exit non-zero.

#include <filesystem>
#include <stdexcept>
#include <string>

namespace ademono {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "path: message" or "path:line: message".
[[noreturn]] void ThrowInputError(const std::filesystem::path& path, const std::string& message);
[[noreturn]] void ThrowInputError(const std::filesystem::path& path, size_t line,
                                  const std::string& message);

// Throws InputError unless `path` exists (and is a directory / regular file when asked).
void RequireFile(const std::filesystem::path& path);
void RequireDirectory(const std::filesystem::path& path);

}  // namespace ademono
