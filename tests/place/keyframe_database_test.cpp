#include "ademono/place/keyframe_database.h"

#include <gtest/gtest.h>

#include <cstdint>

namespace ademono {
namespace {

// Random descriptors from a fixed LCG (portable).
cv::Mat RandomDescriptors(int rows, uint64_t seed) {
  cv::Mat d(rows, 32, CV_8UC1);
  uint64_t s = seed * 6364136223846793005ull + 1442695040888963407ull;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < 32; ++c) {
      s = s * 6364136223846793005ull + 1442695040888963407ull;
      d.at<uint8_t>(r, c) = static_cast<uint8_t>(s >> 56);
    }
  }
  return d;
}

// Flips `flips` random bits of every row (a re-observation of the same features).
cv::Mat Perturb(const cv::Mat& d, int flips, uint64_t seed) {
  cv::Mat out = d.clone();
  uint64_t s = seed;
  for (int r = 0; r < out.rows; ++r) {
    for (int f = 0; f < flips; ++f) {
      s = s * 6364136223846793005ull + 1442695040888963407ull;
      const int bit = static_cast<int>((s >> 33) % 256);
      out.at<uint8_t>(r, bit / 8) ^= static_cast<uint8_t>(1u << (bit % 8));
    }
  }
  return out;
}

TEST(KeyFrameDatabase, FindsTheRevisitedKeyFrameAmongDistractors) {
  KeyFrameDatabase db;
  std::vector<cv::Mat> places;
  for (uint64_t id = 0; id < 200; ++id) {
    places.push_back(RandomDescriptors(500, id + 1));
    db.Add(id, places.back());
  }
  EXPECT_EQ(db.Size(), 200u);
  int top1 = 0;
  for (uint64_t id = 0; id < 200; id += 10) {
    // 60 % of the features seen again with 12 flipped bits of 256, plus new ones.
    cv::Mat query;
    cv::vconcat(Perturb(places[id].rowRange(0, 300), 12, id + 7), RandomDescriptors(200, 9000 + id),
                query);
    const auto candidates = db.Query(query, 5);
    ASSERT_FALSE(candidates.empty());
    if (candidates[0].keyframe_id == id) ++top1;
    EXPECT_GT(candidates[0].score, 0.0);
    EXPECT_LE(candidates[0].score, 1.0);
    for (size_t i = 1; i < candidates.size(); ++i)
      EXPECT_GE(candidates[i - 1].score, candidates[i].score);
  }
  EXPECT_EQ(top1, 20);
}

TEST(KeyFrameDatabase, ExcludeAndEraseRemoveCandidates) {
  KeyFrameDatabase db;
  const cv::Mat a = RandomDescriptors(400, 1), b = RandomDescriptors(400, 2);
  db.Add(10, a);
  db.Add(11, b);
  db.Add(12, RandomDescriptors(400, 3));
  ASSERT_EQ(db.Query(a, 1).at(0).keyframe_id, 10u);
  const auto excluded = db.Query(a, 3, {10});
  for (const auto& c : excluded) EXPECT_NE(c.keyframe_id, 10u);
  db.Erase(10);
  EXPECT_EQ(db.Size(), 2u);
  EXPECT_FALSE(db.Contains(10));
  for (const auto& c : db.Query(a, 3)) EXPECT_NE(c.keyframe_id, 10u);
  db.Erase(10);  // idempotent
  db.Add(11, a);  // re-adding replaces
  EXPECT_EQ(db.Size(), 2u);
  EXPECT_EQ(db.Query(a, 1).at(0).keyframe_id, 11u);
}

TEST(KeyFrameDatabase, SameInputSameCandidates) {
  auto build = [] {
    KeyFrameDatabase db;
    for (uint64_t id = 0; id < 50; ++id) db.Add(id, RandomDescriptors(300, id % 7 + 1));
    return db.Query(RandomDescriptors(300, 3), 20);
  };
  const auto a = build(), b = build();
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), 20u);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].keyframe_id, b[i].keyframe_id);
    EXPECT_EQ(a[i].score, b[i].score);
  }
  // Identical documents tie: the lower id comes first.
  for (size_t i = 1; i < a.size(); ++i) {
    if (a[i - 1].score == a[i].score) {
      EXPECT_LT(a[i - 1].keyframe_id, a[i].keyframe_id);
    }
  }
}

TEST(KeyFrameDatabase, EmptyInputsAndBadDescriptors) {
  KeyFrameDatabase db;
  EXPECT_TRUE(db.Query(RandomDescriptors(10, 1), 5).empty());
  db.Add(0, cv::Mat());
  EXPECT_EQ(db.Size(), 1u);
  EXPECT_TRUE(db.Query(cv::Mat(), 5).empty());
  EXPECT_THROW(db.Add(1, cv::Mat(3, 16, CV_8UC1)), std::invalid_argument);
  EXPECT_THROW(db.Query(cv::Mat(3, 32, CV_32FC1), 1), std::invalid_argument);
}

TEST(KeyFrameDatabaseOptions, TableRoundTripAndRanges) {
  KeyFrameDatabaseOptions o;
  o.bits_per_table = 12;
  const auto back = KeyFrameDatabaseOptions::FromYaml(o.ToYaml());
  EXPECT_EQ(back.bits_per_table, 12);
  EXPECT_THROW(KeyFrameDatabaseOptions::FromYaml(YAML::Load("bits_per_table: 40")),
               std::invalid_argument);
  EXPECT_THROW(KeyFrameDatabaseOptions::FromYaml(YAML::Load("num_tables: 16\nbits_per_table: 20")),
               std::invalid_argument);
  EXPECT_THROW(KeyFrameDatabaseOptions::FromYaml(YAML::Load("nope: 1")), std::invalid_argument);
}

}  // namespace
}  // namespace ademono
