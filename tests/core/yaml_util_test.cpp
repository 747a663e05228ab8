#include "ademono/core/yaml_util.h"

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

namespace ademono {
namespace {

// The std::invalid_argument message of `f`, or "no error".
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

TEST(YamlUtil, ReadYamlKeyKeepsDefaultsAndConverts) {
  const YAML::Node node = YAML::Load("{n: 3, x: 1.5, flag: true, list: [1, 2, 3]}");
  EXPECT_EQ(ReadYamlKey(node, "s", "n", 7), 3);
  EXPECT_EQ(ReadYamlKey(node, "s", "missing", 7), 7);
  EXPECT_DOUBLE_EQ(ReadYamlKey(node, "s", "x", 0.0), 1.5);
  EXPECT_TRUE(ReadYamlKey(node, "s", "flag", false));
  EXPECT_EQ(ReadYamlKey(node, "s", "list", std::vector<int>{}), (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(ReadYamlKey(node, "s", "list", std::array<double, 3>{}),
            (std::array<double, 3>{1, 2, 3}));
  // Absent or null sections and non-map nodes give the fallback.
  EXPECT_EQ(ReadYamlKey(YAML::Node(), "s", "n", 7), 7);
  EXPECT_EQ(ReadYamlKey(YAML::Load("~"), "s", "n", 7), 7);
  EXPECT_EQ(ReadYamlKey(node["missing"], "s", "n", 7), 7);
}

TEST(YamlUtil, ReadYamlKeyErrorsNameSectionKeyAndValue) {
  const YAML::Node node = YAML::Load("{n: many, list: [1, 2], map: {a: 1}, empty: }");
  EXPECT_EQ(ErrorOf([&] { ReadYamlKey(node, "tracking", "n", 7); }),
            "tracking.n: cannot parse 'many'");
  EXPECT_EQ(ErrorOf([&] { ReadYamlKey(node, "input", "list", std::array<double, 3>{}); }),
            "input.list: cannot parse '[1, 2]'");
  EXPECT_EQ(ErrorOf([&] { ReadYamlKey(node, "s", "map", 1.0, "a number"); }),
            "s.map: cannot parse '{a: 1}', expected a number");
  EXPECT_EQ(ErrorOf([&] { ReadYamlKey(node, "s", "empty", 1); }), "s.empty: has no value");
}

TEST(YamlUtil, ReadYamlChoice) {
  enum class Kind { kA, kB };
  const YAML::Node node = YAML::Load("{kind: b, bad: c, blank: ''}");
  auto read = [&](const char* key) {
    return ReadYamlChoice<Kind>(node, "out", key, {{"a", Kind::kA}, {"b", Kind::kB}}, Kind::kA);
  };
  EXPECT_EQ(read("kind"), Kind::kB);
  EXPECT_EQ(read("missing"), Kind::kA);
  EXPECT_EQ(read("blank"), Kind::kA);  // "" keeps the default
  EXPECT_EQ(ErrorOf([&] { read("bad"); }), "out.bad: cannot parse 'c', expected one of a, b");
}

TEST(YamlUtil, CheckYamlKeys) {
  EXPECT_NO_THROW(CheckYamlKeys(YAML::Load("{a: 1, b: 2}"), "s", {"a", "b", "c"}));
  EXPECT_NO_THROW(CheckYamlKeys(YAML::Node(), "s", {"a"}));
  EXPECT_NO_THROW(CheckYamlKeys(YAML::Load("~"), "s", {"a"}));  // empty section
  EXPECT_EQ(ErrorOf([] { CheckYamlKeys(YAML::Load("{a: 1, bogus: 2}"), "s", {"a"}); }),
            "unknown key 's.bogus'");
  EXPECT_EQ(ErrorOf([] { CheckYamlKeys(YAML::Load("[1, 2]"), "s", {"a"}); }), "'s' must be a map");
  EXPECT_EQ(ErrorOf([] { CheckYamlKeys(YAML::Load("{[x, y]: 1}"), "s", {"a"}); }),
            "unknown key 's.[x, y]'");
}

}  // namespace
}  // namespace ademono
