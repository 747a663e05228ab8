#include "ademono/dnn/model_arg.h"

#include <algorithm>

#include "ademono/core/error.h"

namespace ademono {

ModelArg ParseModelArg(const std::string& argument, const std::vector<std::string>& known_keys) {
  ModelArg result;
  // The path ends at the first ",key=" with a known key.
  size_t end = std::string::npos;
  for (const auto& key : known_keys) {
    const size_t at = argument.find("," + key + "=");
    if (at != std::string::npos) end = std::min(end, at);
  }
  // Anything else after a comma that looks like an option is a typo worth reporting.
  if (end == std::string::npos) {
    const size_t comma = argument.rfind(',');
    if (comma != std::string::npos && argument.find('=', comma) != std::string::npos) {
      end = comma;
    }
  }
  result.file = argument.substr(0, end);
  if (result.file.empty()) {
    throw InputError("model spec '" + argument +
                     "' has no file: expected model:FILE.onnx[,key=value]");
  }
  std::string rest = end == std::string::npos ? "" : argument.substr(end + 1);
  while (!rest.empty()) {
    // Values may hold commas only if the next part is not "known_key=".
    size_t next = std::string::npos;
    for (const auto& key : known_keys) {
      const size_t at = rest.find("," + key + "=");
      if (at != std::string::npos) next = std::min(next, at);
    }
    const std::string item = rest.substr(0, next);
    rest = next == std::string::npos ? "" : rest.substr(next + 1);
    const size_t eq = item.find('=');
    if (eq == std::string::npos) {
      throw InputError("model option '" + item + "' is not key=value");
    }
    const std::string key = item.substr(0, eq);
    if (std::find(known_keys.begin(), known_keys.end(), key) == known_keys.end()) {
      std::string expected;
      for (const auto& k : known_keys) expected += (expected.empty() ? "" : ", ") + k;
      throw InputError("unknown model option '" + key + "' (expected " + expected + ")");
    }
    if (!result.options.emplace(key, item.substr(eq + 1)).second) {
      throw InputError("model option '" + key + "' given twice");
    }
  }
  return result;
}

}  // namespace ademono
