#pragma once
// Reading Options structs from a config sub-node: absent keys keep their defaults, keys that do
// not convert raise std::invalid_argument "section.key: cannot parse 'text'" (the CLI adds the
// file name).

#include <stdexcept>
#include <string>
#include <string_view>

#include <yaml-cpp/yaml.h>

namespace ademono {

template <typename T>
T ReadYamlKey(const YAML::Node& node, std::string_view section, const char* key, T fallback) {
  if (!node || !node.IsMap()) return fallback;
  const YAML::Node value = node[key];
  if (!value) return fallback;
  try {
    return value.as<T>();
  } catch (const YAML::Exception&) {
    throw std::invalid_argument(std::string(section) + "." + key + ": cannot parse '" +
                                (value.IsScalar() ? value.Scalar() : std::string("<non-scalar>")) +
                                "'");
  }
}

}  // namespace ademono
