#pragma once
// Parses the argument of a `model:` provider spec: "FILE.onnx[,key=value...]".
// The file is everything before the first ",key=" whose key is a known option, so paths may hold
// commas. Unknown or repeated keys, a missing '=' or an empty path throw InputError.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace ademono {

struct ModelArg {
  std::filesystem::path file;
  std::map<std::string, std::string> options;
};

ModelArg ParseModelArg(const std::string& argument, const std::vector<std::string>& known_keys);

}  // namespace ademono
