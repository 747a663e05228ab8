#pragma once
// One field table per Options struct: each YAML key is written once, as a row {key, member,
// range}, and the table drives the strict reader, the range part of Check() and ToYaml():
//
//   const OptionsTable<OrbOptions>& OrbOptions::Table() {
//     static const auto table = OptionsTable<OrbOptions>("orb")
//         .Add("num_features", &OrbOptions::num_features, Range::Above(0))
//         .Add("scale_factor", &OrbOptions::scale_factor, Range::Above(1));
//     return table;
//   }
//   OrbOptions OrbOptions::FromYaml(const YAML::Node& node) {
//     OrbOptions o;
//     Table().Read(node, o);  // unknown keys and bad values throw
//     o.Check();              // Table().CheckRanges(*this) + the cross-field rules
//     return o;
//   }
//
// Messages are the yaml_util ones, one line naming the key ("section.key: cannot parse 'x'",
// "unknown key 'section.key'", "'section' must be a map") plus the range rule
// ("section.key must be in [0, 1], got 1.5"). They throw std::invalid_argument; the caller that
// knows the file prefixes it (ThrowInputError(path, e.what())).
//
// ToYaml writes every key of the table in table order, numbers in their shortest text that reads
// back to the same value, so Read(Write(x)) == x.

#include <yaml-cpp/yaml.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "ademono/core/yaml_util.h"

namespace ademono {

// A simple range rule for a number, checked by OptionsTable::CheckRanges. Floating values must
// also be finite whenever a rule is given.
struct Range {
  bool has_low = false, low_open = false, has_high = false, high_open = false;
  double low = 0, high = 0;

  static Range None() { return {}; }
  static Range AtLeast(double low) { return {true, false, false, false, low, 0}; }
  static Range Above(double low) { return {true, true, false, false, low, 0}; }
  static Range Closed(double low, double high) { return {true, false, true, false, low, high}; }
  static Range OpenClosed(double low, double high) { return {true, true, true, false, low, high}; }
  static Range ClosedOpen(double low, double high) { return {true, false, true, true, low, high}; }

  bool Empty() const { return !has_low && !has_high; }
  bool Contains(double v) const {
    if (has_low && !(low_open ? v > low : v >= low)) return false;
    if (has_high && !(high_open ? v < high : v <= high)) return false;
    return true;
  }
  // "must be >= 0", "must be in (0, 1]".
  std::string Describe() const;
};

namespace options_internal {

std::string FormatNumber(double v);  // shortest text, "0.02", "30", "-1"

// YAML text of one value that reads back (as<T>) to exactly the same value.
template <typename T>
YAML::Node Encode(const T& value) {
  if constexpr (std::is_same_v<T, bool>) {
    return YAML::Node(value ? "true" : "false");
  } else if constexpr (std::is_arithmetic_v<T>) {
    std::array<char, 64> buffer{};
    const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
    return YAML::Node(std::string(buffer.data(), result.ptr));
  } else if constexpr (std::is_same_v<T, std::string>) {
    return YAML::Node(value);
  } else {  // std::vector / std::array of numbers: a flow list
    YAML::Node list(YAML::NodeType::Sequence);
    for (const auto& item : value) list.push_back(Encode(item));
    list.SetStyle(YAML::EmitterStyle::Flow);
    return list;
  }
}

}  // namespace options_internal

template <typename Options>
class OptionsTable {
 public:
  // Reads the value of one key (present in the section) into the options.
  using ReadFn =
      std::function<void(const YAML::Node& value, const YAML::Node& section, Options& options)>;
  using WriteFn = std::function<YAML::Node(const Options& options)>;
  using CheckFn = std::function<void(const Options& options)>;

  // `section` names the YAML sub-node in messages ("orb", "input", "(root)").
  explicit OptionsTable(std::string section) : section_(std::move(section)) {}

  const std::string& Section() const { return section_; }

  // An empty section (`input:` with nothing under it) is an error instead of "all defaults".
  OptionsTable&& RejectEmpty() && {
    reject_empty_ = true;
    return std::move(*this);
  }

  // A key stored in a member (or a member of a nested struct: Add(key, &O::sub, &Sub::member)).
  template <typename T>
  OptionsTable&& Add(const char* key, T Options::*member, Range range = Range::None()) && {
    return std::move(*this).AddAt(
        key, [member](auto& o) -> auto& { return o.*member; }, range);
  }
  template <typename Sub, typename T>
  OptionsTable&& Add(const char* key, Sub Options::*sub, T Sub::*member,
                     Range range = Range::None()) && {
    return std::move(*this).AddAt(
        key, [ sub, member ](auto& o) -> auto& { return (o.*sub).*member; }, range);
  }

  // A key whose text is one of `choices`; ToYaml writes the first name of the stored value.
  template <typename T>
  OptionsTable&& AddChoice(const char* key, T Options::*member,
                           std::vector<std::pair<std::string, T>> choices) && {
    Row row;
    row.key = key;
    const std::string section = section_;
    row.read = [section, key, member, choices](const YAML::Node& value, const YAML::Node&,
                                               Options& o) {
      o.*member = ReadChoice(section, key, value, choices, o.*member);
    };
    row.write = [member, choices](const Options& o) {
      for (const auto& [name, choice] : choices) {
        if (choice == o.*member) return YAML::Node(name);
      }
      throw std::logic_error("OptionsTable: value without a name");
    };
    rows_.push_back(std::move(row));
    return std::move(*this);
  }

  // A key read and written by hand (a value with two spellings, units, ...).
  OptionsTable&& AddCustom(const char* key, ReadFn read, WriteFn write) && {
    Row row;
    row.key = key;
    row.read = std::move(read);
    row.write = std::move(write);
    rows_.push_back(std::move(row));
    return std::move(*this);
  }

  // A nested section (`orb:` under the root) read by its own table into `member`.
  template <typename Sub>
  OptionsTable&& AddSection(const char* key, Sub Options::*member,
                            const OptionsTable<Sub>& sub) && {
    Row row;
    row.key = key;
    row.read = [member, &sub](const YAML::Node& value, const YAML::Node&, Options& o) {
      sub.Read(value, o.*member);
    };
    row.write = [member, &sub](const Options& o) { return sub.Write(o.*member); };
    row.check = [member, &sub](const Options& o) { sub.CheckRanges(o.*member); };
    rows_.push_back(std::move(row));
    return std::move(*this);
  }
  // A nested section whose keys are stored in the same struct (the model spec's `input:`).
  OptionsTable&& AddSection(const char* key, const OptionsTable<Options>& sub) && {
    Row row;
    row.key = key;
    row.read = [&sub](const YAML::Node& value, const YAML::Node&, Options& o) {
      sub.Read(value, o);
    };
    row.write = [&sub](const Options& o) { return sub.Write(o); };
    row.check = [&sub](const Options& o) { sub.CheckRanges(o); };
    rows_.push_back(std::move(row));
    return std::move(*this);
  }

  // The keys of `sub` stored in `member`, read from this same node (a flat YAML section whose
  // keys fill a nested struct, as `filter:` fills FilterOptions::dynamic).
  template <typename Sub>
  OptionsTable&& AddFlat(Sub Options::*member, const OptionsTable<Sub>& sub) && {
    for (const auto& inner : sub.rows_) {
      Row row;
      row.key = inner.key;
      if (inner.read) {
        row.read = [member, read = inner.read](const YAML::Node& value, const YAML::Node& node,
                                               Options& o) { read(value, node, o.*member); };
      }
      if (inner.write) {
        row.write = [member, write = inner.write](const Options& o) { return write(o.*member); };
      }
      if (inner.check) {
        row.check = [member, check = inner.check](const Options& o) { check(o.*member); };
      }
      rows_.push_back(std::move(row));
    }
    return std::move(*this);
  }

  // A key that is accepted and left to another reader (not read, not written).
  OptionsTable&& AddIgnored(const char* key) && {
    Row row;
    row.key = key;
    rows_.push_back(std::move(row));
    return std::move(*this);
  }

  // Strict read: every key of `node` must be in the table; absent keys keep their values in
  // `options`. An absent or null node keeps everything (unless RejectEmpty()).
  void Read(const YAML::Node& node, Options& options) const {
    if (node && node.IsNull() && reject_empty_)
      throw std::invalid_argument("'" + section_ + "' is empty, expected a map");
    if (!node || node.IsNull()) {
      return;
    }
    if (!node.IsMap()) throw std::invalid_argument("'" + section_ + "' must be a map");
    for (const auto& entry : node) {
      const std::string key = YamlText(entry.first);
      if (Find(key) == nullptr)
        throw std::invalid_argument("unknown key '" + section_ + "." + key + "'");
    }
    for (const Row& row : rows_) {
      if (!row.read) continue;
      const YAML::Node value = node[row.key];
      if (value) row.read(value, node, options);
    }
  }

  // Every key of the table (ignored keys excepted), in table order.
  YAML::Node Write(const Options& options) const {
    YAML::Node node(YAML::NodeType::Map);
    for (const Row& row : rows_) {
      if (row.write) node[row.key] = row.write(options);
    }
    return node;
  }

  // Throws std::invalid_argument "section.key must be ..., got v" for the first value outside
  // its range (nested sections included).
  void CheckRanges(const Options& options) const {
    for (const Row& row : rows_) {
      if (row.check) row.check(options);
    }
  }

  // The keys, in table order (documentation, tests).
  std::vector<std::string> Keys() const {
    std::vector<std::string> keys;
    for (const Row& row : rows_) keys.push_back(row.key);
    return keys;
  }

 private:
  template <typename Other>
  friend class OptionsTable;

  struct Row {
    std::string key;
    ReadFn read;
    WriteFn write;
    CheckFn check;
  };

  const Row* Find(const std::string& key) const {
    for (const Row& row : rows_) {
      if (row.key == key) return &row;
    }
    return nullptr;
  }

  template <typename Access>
  OptionsTable&& AddAt(const char* key, Access access, Range range) && {
    using T = std::remove_cvref_t<decltype(access(std::declval<Options&>()))>;
    const std::string section = section_;
    Row row;
    row.key = key;
    row.read = [section, key, access](const YAML::Node&, const YAML::Node& node, Options& o) {
      T& field = access(o);
      field = ReadYamlKey<T>(node, section, key, field);
    };
    row.write = [access](const Options& o) { return options_internal::Encode(access(o)); };
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      if (!range.Empty()) {
        row.check = [section, key, access, range](const Options& o) {
          const double v = static_cast<double>(access(o));
          if (!std::isfinite(v) || !range.Contains(v)) {
            throw std::invalid_argument(section + "." + key + " " + range.Describe() + ", got " +
                                        options_internal::FormatNumber(v));
          }
        };
      }
    } else if constexpr (std::is_same_v<T, std::vector<int>>) {
      if (!range.Empty()) {  // the rule applies to every element
        row.check = [section, key, access, range](const Options& o) {
          for (int v : access(o)) {
            if (!range.Contains(v)) {
              throw std::invalid_argument(section + "." + key + " entries " + range.Describe() +
                                          ", got " + std::to_string(v));
            }
          }
        };
      }
    } else {
      if (!range.Empty()) throw std::logic_error("OptionsTable: a range needs a number");
    }
    rows_.push_back(std::move(row));
    return std::move(*this);
  }

  template <typename T>
  static T ReadChoice(const std::string& section, const char* key, const YAML::Node& value,
                      const std::vector<std::pair<std::string, T>>& choices, T fallback) {
    std::string text;
    try {
      text = value.as<std::string>();
    } catch (const YAML::Exception&) {
      ThrowBadYamlValue(section, key, value);
    }
    if (text.empty()) return fallback;  // as ReadYamlChoice: "" keeps the default
    std::string names;
    for (const auto& [name, choice] : choices) {
      if (name == text) return choice;
      names += (names.empty() ? "" : ", ") + name;
    }
    ThrowBadYamlValue(section, key, value, "one of " + names);
  }

  std::string section_;
  bool reject_empty_ = false;
  std::vector<Row> rows_;
};

// YAML text of a table's output, block style with flow lists ("key: [1, 2]").
std::string YamlToText(const YAML::Node& node);

// The usual FromYaml of an Options struct with a Table() and a Check(): defaults, then the node's
// keys (strict), then every rule.
template <typename Options>
Options ReadOptions(const YAML::Node& node) {
  Options options;
  Options::Table().Read(node, options);
  options.Check();
  return options;
}

}  // namespace ademono
