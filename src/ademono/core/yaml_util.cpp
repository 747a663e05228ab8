#include "ademono/core/yaml_util.h"

namespace ademono {

std::string YamlText(const YAML::Node& value) {
  if (!value || value.IsNull()) return "";
  if (value.IsScalar()) return value.Scalar();
  YAML::Emitter out;
  out.SetSeqFormat(YAML::Flow);
  out.SetMapFormat(YAML::Flow);
  out << value;
  return out.c_str();
}

void ThrowBadYamlValue(std::string_view section, std::string_view key, const YAML::Node& value,
                       std::string_view expected) {
  std::string message = std::string(section) + "." + std::string(key) + ": ";
  message += value.IsNull() ? "has no value" : "cannot parse '" + YamlText(value) + "'";
  if (!expected.empty()) message += ", expected " + std::string(expected);
  throw std::invalid_argument(message);
}

void CheckYamlKeys(const YAML::Node& node, std::string_view section,
                   std::initializer_list<std::string_view> keys) {
  if (!node || node.IsNull()) return;
  if (!node.IsMap()) throw std::invalid_argument("'" + std::string(section) + "' must be a map");
  for (const auto& entry : node) {
    const std::string key = YamlText(entry.first);
    bool known = false;
    for (std::string_view k : keys) known = known || key == k;
    if (!known)
      throw std::invalid_argument("unknown key '" + std::string(section) + "." + key + "'");
  }
}

}  // namespace ademono
