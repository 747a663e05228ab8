#include "ademono/core/options_table.h"

namespace ademono {

std::string Range::Describe() const {
  const std::string lo = options_internal::FormatNumber(low);
  const std::string hi = options_internal::FormatNumber(high);
  if (has_low && has_high)
    return "must be in " + std::string(low_open ? "(" : "[") + lo + ", " + hi +
           (high_open ? ")" : "]");
  if (has_low) return std::string("must be ") + (low_open ? "> " : ">= ") + lo;
  if (has_high) return std::string("must be ") + (high_open ? "< " : "<= ") + hi;
  return "must be finite";
}

namespace options_internal {

std::string FormatNumber(double v) {
  std::ostringstream out;
  out << v;  // 6 significant digits: enough for a message
  return out.str();
}

}  // namespace options_internal

std::string YamlToText(const YAML::Node& node) {
  YAML::Emitter out;
  out << node;
  return std::string(out.c_str()) + "\n";
}

}  // namespace ademono
