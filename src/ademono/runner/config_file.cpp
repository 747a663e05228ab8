#include "ademono/runner/config_file.h"

#include <regex>

#include "ademono/core/error.h"

namespace fs = std::filesystem;

namespace ademono {

YAML::Node LoadConfigWithOverrides(const fs::path& path,
                                   const std::vector<std::string>& overrides) {
  YAML::Node config;
  if (!path.empty()) {
    RequireFile(path);
    try {
      config = YAML::LoadFile(path.string());
    } catch (const YAML::Exception& e) {
      ThrowInputError(path, std::string("invalid YAML: ") + e.msg);
    }
  }
  static const std::regex pattern("^([A-Za-z_][A-Za-z0-9_]*)\\.([A-Za-z_][A-Za-z0-9_]*)=(.*)$");
  for (const std::string& item : overrides) {
    std::smatch m;
    if (!std::regex_match(item, m, pattern)) {
      throw InputError("--set '" + item + "': expected SECTION.KEY=VALUE (e.g. depth.max_depth=8)");
    }
    try {
      const YAML::Node value = YAML::Load(m[3].str());
      if (!config || !config.IsMap()) config = YAML::Node(YAML::NodeType::Map);
      config[m[1].str()][m[2].str()] = value;
    } catch (const YAML::Exception& e) {
      throw InputError("--set '" + item + "': invalid YAML value: " + e.msg);
    }
  }
  return config;
}

}  // namespace ademono
