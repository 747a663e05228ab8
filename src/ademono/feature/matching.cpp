#include "ademono/feature/matching.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace ademono {
namespace {

void CheckDescriptors(const cv::Mat& d, const char* what) {
  if (d.empty()) return;
  if (d.type() != CV_8UC1 || d.cols != 32)
    throw std::invalid_argument(std::string("MatchBruteForce: ") + what +
                                " descriptors must be CV_8UC1 with 32 columns");
}

// Hamming distance of two 32-byte rows given as raw pointers (no cv::Mat headers in the hot loop).
[[gnu::always_inline]] inline int RowDistance(const uchar* a, const uchar* b) {
  int distance = 0;
  for (int i = 0; i < 4; ++i) {
    uint64_t wa, wb;
    std::memcpy(&wa, a + 8 * i, 8);
    std::memcpy(&wb, b + 8 * i, 8);
    distance += std::popcount(wa ^ wb);
  }
  return distance;
}

// Best and second-best distance of `query_row` over all train rows. The loop is compiled twice on
// x86-64: with the POPCNT instruction (picked at run time when the CPU has it; 8x faster in
// bench_feature) and for the baseline ISA. Both give identical results.
struct BestTwo {
  int best = std::numeric_limits<int>::max();
  int second = std::numeric_limits<int>::max();
  int best_idx = -1;
};

[[gnu::always_inline]] inline BestTwo ScanRows(const uchar* query_row, const cv::Mat& train) {
  BestTwo r;
  for (int t = 0; t < train.rows; ++t) {
    const int d = RowDistance(query_row, train.ptr<uchar>(t));
    if (d < r.best) {
      r.second = r.best;
      r.best = d;
      r.best_idx = t;
    } else if (d < r.second) {
      r.second = d;
    }
  }
  return r;
}

#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("popcnt"))) BestTwo ScanRowsPopcnt(const uchar* query_row,
                                                         const cv::Mat& train) {
  return ScanRows(query_row, train);
}
BestTwo Scan(const uchar* query_row, const cv::Mat& train) {
  static const bool has_popcnt = __builtin_cpu_supports("popcnt");
  return has_popcnt ? ScanRowsPopcnt(query_row, train) : ScanRows(query_row, train);
}
__attribute__((target("popcnt"))) int RowDistancePopcnt(const uchar* a, const uchar* b) {
  return RowDistance(a, b);
}
int Distance(const uchar* a, const uchar* b) {
  static const bool has_popcnt = __builtin_cpu_supports("popcnt");
  return has_popcnt ? RowDistancePopcnt(a, b) : RowDistance(a, b);
}
#else
BestTwo Scan(const uchar* query_row, const cv::Mat& train) { return ScanRows(query_row, train); }
int Distance(const uchar* a, const uchar* b) { return RowDistance(a, b); }
#endif

}  // namespace

int DescriptorDistance(const cv::Mat& a, const cv::Mat& b) {
  return Distance(a.ptr<uchar>(), b.ptr<uchar>());
}

int DescriptorDistance(const uchar* a, const uchar* b) { return Distance(a, b); }

RotationHistogram::RotationHistogram(int num_bins) {
  if (num_bins < 1) throw std::invalid_argument("RotationHistogram: num_bins must be >= 1");
  bins_.resize(num_bins);
}

void RotationHistogram::Add(float angle_from_deg, float angle_to_deg, int match_index) {
  float rotation = angle_from_deg - angle_to_deg;
  rotation = std::fmod(rotation, 360.f);
  if (rotation < 0.f) rotation += 360.f;
  const int num_bins = NumBins();
  // rotation * (bins / 360), rounded, in float: the arithmetic the tracker's results rest on.
  const float factor = static_cast<float>(num_bins) / 360.f;
  int bin = static_cast<int>(std::round(rotation * factor));
  if (bin == num_bins) bin = 0;
  bin = std::clamp(bin, 0, num_bins - 1);
  bins_[bin].push_back(match_index);
}

std::vector<bool> RotationHistogram::DominantBins() const {
  // The three largest bins; equal counts go to the lower bin index.
  int best[3] = {-1, -1, -1};
  auto count = [&](int b) { return b < 0 ? -1 : static_cast<int>(bins_[b].size()); };
  for (int b = 0; b < NumBins(); ++b) {
    const int n = static_cast<int>(bins_[b].size());
    if (n > count(best[0])) {
      best[2] = best[1];
      best[1] = best[0];
      best[0] = b;
    } else if (n > count(best[1])) {
      best[2] = best[1];
      best[1] = b;
    } else if (n > count(best[2])) {
      best[2] = b;
    }
  }
  std::vector<bool> dominant(bins_.size(), false);
  const int top = count(best[0]);
  if (top <= 0) return dominant;
  dominant[best[0]] = true;
  // Weaker peaks count only if they are a real mode (>= 10% of the strongest), as in ORB-SLAM.
  if (count(best[1]) >= 0.1 * top && count(best[1]) > 0) {
    dominant[best[1]] = true;
    if (count(best[2]) >= 0.1 * top && count(best[2]) > 0) dominant[best[2]] = true;
  }
  return dominant;
}

std::vector<int> RotationHistogram::InconsistentMatches() const {
  const std::vector<bool> dominant = DominantBins();
  std::vector<int> out;
  for (int b = 0; b < NumBins(); ++b)
    if (!dominant[b]) out.insert(out.end(), bins_[b].begin(), bins_[b].end());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<int> RotationHistogram::ConsistentMatches() const {
  const std::vector<bool> dominant = DominantBins();
  std::vector<int> out;
  for (int b = 0; b < NumBins(); ++b)
    if (dominant[b]) out.insert(out.end(), bins_[b].begin(), bins_[b].end());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<cv::DMatch> MatchBruteForce(const cv::Mat& query, const cv::Mat& train,
                                        const BruteForceMatchOptions& options) {
  CheckDescriptors(query, "query");
  CheckDescriptors(train, "train");
  std::vector<cv::DMatch> matches;
  if (query.empty() || train.empty()) return matches;
  for (int q = 0; q < query.rows; ++q) {
    const auto [best, second, best_idx] = Scan(query.ptr<uchar>(q), train);
    if (best_idx < 0 || best > options.max_distance) continue;
    // With a single train row there is no second best: the ratio test passes.
    if (second != std::numeric_limits<int>::max() &&
        !(static_cast<double>(best) < options.ratio * second))
      continue;
    matches.emplace_back(q, best_idx, static_cast<float>(best));
  }
  if (options.unique_train) {
    // Keep the closest query for each train row (lowest query index on ties).
    std::vector<int> owner(train.rows, -1);
    for (size_t i = 0; i < matches.size(); ++i) {
      int& o = owner[matches[i].trainIdx];
      if (o < 0 || matches[i].distance < matches[o].distance) o = static_cast<int>(i);
    }
    std::vector<cv::DMatch> unique;
    for (size_t i = 0; i < matches.size(); ++i)
      if (owner[matches[i].trainIdx] == static_cast<int>(i)) unique.push_back(matches[i]);
    matches = std::move(unique);
  }
  return matches;
}

}  // namespace ademono
