#include "ademono/core/options_table.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace ademono {
namespace {

struct Inner {
  int count = 3;
  bool operator==(const Inner&) const = default;
};

enum class Mode { kFast, kSlow };

struct Demo {
  int n = 7;
  double ratio = 0.1;
  float gain = 1.2f;
  bool flag = false;
  uint64_t seed = 42;
  std::string name = "demo";
  std::vector<int> ids{1, 2};
  Mode mode = Mode::kFast;
  Inner inner;
  Inner nested;
  bool operator==(const Demo&) const = default;
};

const OptionsTable<Inner>& InnerTable() {
  static const auto table =
      OptionsTable<Inner>("inner").Add("count", &Inner::count, Range::AtLeast(1));
  return table;
}

const OptionsTable<Demo>& DemoTable() {
  static const auto table =
      OptionsTable<Demo>("demo")
          .Add("n", &Demo::n, Range::Closed(0, 10))
          .Add("ratio", &Demo::ratio, Range::OpenClosed(0, 1))
          .Add("gain", &Demo::gain, Range::Above(1))
          .Add("flag", &Demo::flag)
          .Add("seed", &Demo::seed)
          .Add("name", &Demo::name)
          .Add("ids", &Demo::ids, Range::AtLeast(0))
          .AddChoice<Mode>("mode", &Demo::mode, {{"fast", Mode::kFast}, {"slow", Mode::kSlow}})
          .Add("inner_count", &Demo::inner, &Inner::count, Range::AtLeast(1))
          .AddSection("nested", &Demo::nested, InnerTable())
          .AddIgnored("other");
  return table;
}

template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

Demo Read(const std::string& text) {
  Demo demo;
  DemoTable().Read(YAML::Load(text), demo);
  return demo;
}

TEST(OptionsTable, ReadsEveryKindOfKeyAndKeepsDefaults) {
  const Demo d = Read(
      "{n: 4, ratio: 0.5, gain: 2.5, flag: true, seed: 18446744073709551615, name: x, ids: [5],"
      " mode: slow, inner_count: 9, nested: {count: 2}, other: {anything: 1}}");
  EXPECT_EQ(d.n, 4);
  EXPECT_EQ(d.ratio, 0.5);
  EXPECT_EQ(d.gain, 2.5f);
  EXPECT_TRUE(d.flag);
  EXPECT_EQ(d.seed, UINT64_MAX);
  EXPECT_EQ(d.name, "x");
  EXPECT_EQ(d.ids, std::vector<int>{5});
  EXPECT_EQ(d.mode, Mode::kSlow);
  EXPECT_EQ(d.inner.count, 9);
  EXPECT_EQ(d.nested.count, 2);
  EXPECT_EQ(Read("{n: 1}").ratio, 0.1);
  EXPECT_EQ(Read("~"), Demo{});
  EXPECT_EQ(Read("{}"), Demo{});
}

TEST(OptionsTable, ErrorsNameSectionAndKey) {
  EXPECT_EQ(ErrorOf([] { Read("{n: 1, bogus: 2}"); }), "unknown key 'demo.bogus'");
  EXPECT_EQ(ErrorOf([] { Read("{nested: {bogus: 2}}"); }), "unknown key 'inner.bogus'");
  EXPECT_EQ(ErrorOf([] { Read("[1, 2]"); }), "'demo' must be a map");
  EXPECT_EQ(ErrorOf([] { Read("{n: many}"); }), "demo.n: cannot parse 'many'");
  EXPECT_EQ(ErrorOf([] { Read("{n: }"); }), "demo.n: has no value");
  EXPECT_EQ(ErrorOf([] { Read("{seed: -1}"); }), "demo.seed: cannot parse '-1'");
  EXPECT_EQ(ErrorOf([] { Read("{mode: medium}"); }),
            "demo.mode: cannot parse 'medium', expected one of fast, slow");
  EXPECT_EQ(Read("{mode: ''}").mode, Mode::kFast);  // as ReadYamlChoice: "" keeps the default
}

TEST(OptionsTable, RejectEmptySection) {
  static const auto strict = OptionsTable<Inner>("inner").RejectEmpty().Add("count", &Inner::count);
  Inner inner;
  EXPECT_EQ(ErrorOf([&] { strict.Read(YAML::Load("~"), inner); }),
            "'inner' is empty, expected a map");
  const YAML::Node root = YAML::Load("{other: 1}");
  EXPECT_NO_THROW(strict.Read(root["inner"], inner));  // absent is fine
}

TEST(OptionsTable, CheckRangesNamesKeyRuleAndValue) {
  Demo d;
  EXPECT_NO_THROW(DemoTable().CheckRanges(d));
  d.n = 11;
  EXPECT_EQ(ErrorOf([&] { DemoTable().CheckRanges(d); }), "demo.n must be in [0, 10], got 11");
  d = Demo{};
  d.ratio = 0;
  EXPECT_EQ(ErrorOf([&] { DemoTable().CheckRanges(d); }), "demo.ratio must be in (0, 1], got 0");
  d = Demo{};
  d.gain = 1;
  EXPECT_EQ(ErrorOf([&] { DemoTable().CheckRanges(d); }), "demo.gain must be > 1, got 1");
  d = Demo{};
  d.ratio = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(ErrorOf([&] { DemoTable().CheckRanges(d); }).substr(0, 30),
            "demo.ratio must be in (0, 1], ");
  d = Demo{};
  d.ids = {3, -1};
  EXPECT_EQ(ErrorOf([&] { DemoTable().CheckRanges(d); }), "demo.ids entries must be >= 0, got -1");
  d = Demo{};
  d.inner.count = 0;
  EXPECT_EQ(ErrorOf([&] { DemoTable().CheckRanges(d); }), "demo.inner_count must be >= 1, got 0");
  d = Demo{};
  d.nested.count = 0;
  EXPECT_EQ(ErrorOf([&] { DemoTable().CheckRanges(d); }), "inner.count must be >= 1, got 0");
}

TEST(OptionsTable, WriteListsEveryKeyAndReadsBackExactly) {
  Demo d;
  d.ratio = 0.1 + 0.2;  // 0.30000000000000004: needs all 17 digits
  d.gain = 1.1f;
  d.seed = 12345678901234567890ull;
  d.mode = Mode::kSlow;
  d.ids = {};
  const YAML::Node node = DemoTable().Write(d);
  EXPECT_EQ(YamlToText(node),
            "n: 7\nratio: 0.30000000000000004\ngain: 1.1\nflag: false\n"
            "seed: 12345678901234567890\nname: demo\nids: []\nmode: slow\ninner_count: 3\n"
            "nested:\n  count: 3\n");
  Demo back;
  DemoTable().Read(YAML::Load(YamlToText(node)), back);
  EXPECT_EQ(back, d);
  EXPECT_EQ(DemoTable().Keys(),
            (std::vector<std::string>{"n", "ratio", "gain", "flag", "seed", "name", "ids", "mode",
                                      "inner_count", "nested", "other"}));
}

}  // namespace
}  // namespace ademono
