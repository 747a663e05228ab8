#include "ademono/filter/distant.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace ademono {
namespace {

TEST(UniformFromBitsTest, Range) {
  EXPECT_EQ(UniformFromBits(0), 0.0);
  EXPECT_LT(UniformFromBits(~uint64_t{0}), 1.0);
  EXPECT_EQ(UniformFromBits(uint64_t{1} << 63), 0.5);
}

TEST(DrawDistantDropsTest, DropRateIsTheProbability) {
  const std::vector<float> depths(20000, 50.f);
  std::mt19937_64 rng(42);
  const std::vector<bool> drop = DrawDistantDrops(depths, {}, 30.0, 0.5, rng);
  int dropped = 0;
  for (bool d : drop) dropped += d ? 1 : 0;
  EXPECT_NEAR(dropped / 20000.0, 0.5, 0.02);
  std::mt19937_64 rng2(42);
  const std::vector<bool> drop30 = DrawDistantDrops(depths, {}, 30.0, 0.3, rng2);
  dropped = 0;
  for (bool d : drop30) dropped += d ? 1 : 0;
  EXPECT_NEAR(dropped / 20000.0, 0.3, 0.02);
}

TEST(DrawDistantDropsTest, DeterministicForASeedAndDrawsOnlyForCandidates) {
  std::vector<float> depths{50.f, 10.f, 0.f,  std::numeric_limits<float>::quiet_NaN(),
                            30.f, 31.f, 40.f, 45.f};
  const std::vector<bool> active{true, true, true, true, true, true, false, true};
  std::mt19937_64 a(7), b(7), reference(7);
  const std::vector<bool> da = DrawDistantDrops(depths, active, 30.0, 0.5, a);
  const std::vector<bool> db = DrawDistantDrops(depths, active, 30.0, 0.5, b);
  EXPECT_EQ(da, db);
  // Candidates: 0 (50 m), 5 (31 m), 7 (45 m); 30 m is not beyond z_th, 6 is inactive.
  const std::vector<size_t> candidates{0, 5, 7};
  for (size_t i = 0; i < depths.size(); ++i) {
    if (std::find(candidates.begin(), candidates.end(), i) == candidates.end()) {
      EXPECT_FALSE(da[i]) << i;
    } else {
      EXPECT_EQ(da[i], UniformFromBits(reference()) < 0.5) << i;
    }
  }
  EXPECT_EQ(a(), reference());  // exactly one draw per candidate
  std::mt19937_64 c(7);
  const std::vector<bool> all = DrawDistantDrops(depths, active, 30.0, 1.0, c);
  const std::vector<bool> none = DrawDistantDrops(depths, active, 30.0, 0.0, c);
  for (size_t i : candidates) {
    EXPECT_TRUE(all[i]);
    EXPECT_FALSE(none[i]);
  }
}

}  // namespace
}  // namespace ademono
