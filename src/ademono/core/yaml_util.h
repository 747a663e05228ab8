#pragma once
// Reading Options structs and specs from a config sub-node, the one implementation for the library.
// `section` is the sub-node's name in messages. Absent keys keep their defaults; a problem raises
// std::invalid_argument with a one-line message naming the key (the caller that knows the file
// adds it, e.g. ThrowInputError(path, e.what())):
//   "section.key: cannot parse 'text'"                    value does not convert
//   "section.key: cannot parse 'text', expected <what>"  when the reader says what it accepts
//   "section.key: has no value"                           `key:` with nothing after it
//   "unknown key 'section.key'"                           CheckYamlKeys
//   "'section' must be a map"                             CheckYamlKeys, node is a list or scalar

#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

namespace ademono {

// The value as written: the scalar text, or flow-style YAML ("[1, 2]") for a list or map.
std::string YamlText(const YAML::Node& value);

// Throws std::invalid_argument "section.key: cannot parse 'text'[, expected <expected>]".
[[noreturn]] void ThrowBadYamlValue(std::string_view section, std::string_view key,
                                    const YAML::Node& value, std::string_view expected = {});

// Throws std::invalid_argument unless `node` is absent, null (an empty section) or a map whose
// keys are all in `keys`.
void CheckYamlKeys(const YAML::Node& node, std::string_view section,
                   std::initializer_list<std::string_view> keys);

// node[key] as T, or `fallback` when node is not a map or has no such key. `expected` (e.g. "a
// list of 3 numbers") is added to the message when the value does not convert.
template <typename T>
T ReadYamlKey(const YAML::Node& node, std::string_view section, const char* key, T fallback,
              std::string_view expected = {}) {
  if (!node || !node.IsMap()) return fallback;
  const YAML::Node value = node[key];
  if (!value) return fallback;
  try {
    return value.as<T>();
  } catch (const YAML::Exception&) {
    ThrowBadYamlValue(section, key, value, expected);
  }
}

// A string key that must be one of `choices` (name -> value); absent or "" keeps `fallback`.
template <typename T>
T ReadYamlChoice(const YAML::Node& node, std::string_view section, const char* key,
                 std::initializer_list<std::pair<std::string_view, T>> choices, T fallback) {
  const std::string text = ReadYamlKey(node, section, key, std::string());
  if (text.empty()) return fallback;
  std::string names;
  for (const auto& [name, choice] : choices) {
    if (name == text) return choice;
    names += (names.empty() ? "" : ", ") + std::string(name);
  }
  ThrowBadYamlValue(section, key, node[key], "one of " + names);
}

}  // namespace ademono
