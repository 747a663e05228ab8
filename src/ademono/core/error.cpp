#include "ademono/core/error.h"

namespace ademono {

void ThrowInputError(const std::filesystem::path& path, const std::string& message) {
  throw InputError(path.string() + ": " + message);
}

void ThrowInputError(const std::filesystem::path& path, size_t line, const std::string& message) {
  throw InputError(path.string() + ":" + std::to_string(line) + ": " + message);
}

void RequireFile(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) ThrowInputError(path, "no such file");
  if (std::filesystem::is_directory(path, ec))
    ThrowInputError(path, "is a directory, expected a file");
}

void RequireDirectory(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) ThrowInputError(path, "no such directory");
  if (!std::filesystem::is_directory(path, ec)) ThrowInputError(path, "is not a directory");
}

}  // namespace ademono
