#include "ademono/place/keyframe_database.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace ademono {

const OptionsTable<KeyFrameDatabaseOptions>& KeyFrameDatabaseOptions::Table() {
  using O = KeyFrameDatabaseOptions;
  static const auto table = OptionsTable<O>("place")
                                .Add("num_tables", &O::num_tables, Range::Closed(1, 16))
                                .Add("bits_per_table", &O::bits_per_table, Range::Closed(4, 24))
                                .Add("seed", &O::seed, Range::AtLeast(0))
                                .Add("max_word_frequency", &O::max_word_frequency,
                                     Range::OpenClosed(0, 1));
  return table;
}

void KeyFrameDatabaseOptions::Check() const {
  Table().CheckRanges(*this);
  if (num_tables * bits_per_table > 256)
    throw std::invalid_argument("place: num_tables * bits_per_table must be <= 256");
}

KeyFrameDatabaseOptions KeyFrameDatabaseOptions::FromYaml(const YAML::Node& node) {
  return ReadOptions<KeyFrameDatabaseOptions>(node);
}

YAML::Node KeyFrameDatabaseOptions::ToYaml() const { return Table().Write(*this); }

namespace {

// splitmix64: a fixed, portable sequence (std:: distributions differ between libraries).
uint64_t SplitMix(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

void CheckDescriptors(const cv::Mat& descriptors) {
  if (!descriptors.empty() && (descriptors.type() != CV_8UC1 || descriptors.cols != 32))
    throw std::invalid_argument("KeyFrameDatabase: descriptors must be CV_8UC1 with 32 columns");
}

}  // namespace

KeyFrameDatabase::KeyFrameDatabase(const KeyFrameDatabaseOptions& options) : options_(options) {
  options_.Check();
  // Disjoint bits per table: a Fisher-Yates shuffle of the 256 bit positions.
  std::vector<int> order(256);
  std::iota(order.begin(), order.end(), 0);
  uint64_t state = static_cast<uint64_t>(options_.seed);
  for (int i = 255; i > 0; --i) {
    const int j = static_cast<int>(SplitMix(state) % static_cast<uint64_t>(i + 1));
    std::swap(order[i], order[j]);
  }
  bits_.resize(options_.num_tables);
  for (int t = 0; t < options_.num_tables; ++t) {
    for (int b = 0; b < options_.bits_per_table; ++b) {
      const int bit = order[t * options_.bits_per_table + b];
      bits_[t].emplace_back(bit / 8, static_cast<uint8_t>(1u << (bit % 8)));
    }
  }
}

std::vector<uint32_t> KeyFrameDatabase::Words(const cv::Mat& descriptors) const {
  CheckDescriptors(descriptors);
  std::vector<uint32_t> words;
  words.reserve(static_cast<size_t>(descriptors.rows) * bits_.size());
  for (int r = 0; r < descriptors.rows; ++r) {
    const uint8_t* d = descriptors.ptr<uint8_t>(r);
    for (size_t t = 0; t < bits_.size(); ++t) {
      uint32_t key = 0;
      for (const auto& [byte, mask] : bits_[t]) key = (key << 1) | ((d[byte] & mask) ? 1u : 0u);
      words.push_back(static_cast<uint32_t>(t << options_.bits_per_table) | key);
    }
  }
  return words;
}

std::vector<std::pair<uint32_t, uint32_t>> KeyFrameDatabase::BagOfWords(
    const cv::Mat& descriptors) const {
  std::vector<uint32_t> words = Words(descriptors);
  std::sort(words.begin(), words.end());
  std::vector<std::pair<uint32_t, uint32_t>> bag;
  for (uint32_t w : words) {
    if (!bag.empty() && bag.back().first == w) {
      ++bag.back().second;
    } else {
      bag.emplace_back(w, 1u);
    }
  }
  return bag;
}

void KeyFrameDatabase::Add(uint64_t keyframe_id, const cv::Mat& descriptors) {
  auto bag = BagOfWords(descriptors);
  std::lock_guard<std::mutex> lock(mutex_);
  EraseLocked(keyframe_id);
  for (const auto& [word, count] : bag) {
    auto& list = inverted_[word];
    // Lists stay sorted by keyframe id (ids usually arrive in order: append).
    const Entry entry{keyframe_id, count};
    if (list.empty() || list.back().keyframe_id < keyframe_id) {
      list.push_back(entry);
    } else {
      list.insert(std::lower_bound(list.begin(), list.end(), entry,
                                   [](const Entry& a, const Entry& b) {
                                     return a.keyframe_id < b.keyframe_id;
                                   }),
                  entry);
    }
  }
  Document& doc = documents_[keyframe_id];
  doc.words = std::move(bag);
  doc.length = static_cast<double>(descriptors.rows);
}

void KeyFrameDatabase::Erase(uint64_t keyframe_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  EraseLocked(keyframe_id);
}

void KeyFrameDatabase::EraseLocked(uint64_t keyframe_id) {
  const auto it = documents_.find(keyframe_id);
  if (it == documents_.end()) return;
  for (const auto& [word, count] : it->second.words) {
    (void)count;
    auto list_it = inverted_.find(word);
    if (list_it == inverted_.end()) continue;
    auto& list = list_it->second;
    const auto pos = std::lower_bound(
        list.begin(), list.end(), keyframe_id,
        [](const Entry& a, uint64_t id) { return a.keyframe_id < id; });
    if (pos != list.end() && pos->keyframe_id == keyframe_id) list.erase(pos);
    if (list.empty()) inverted_.erase(list_it);
  }
  documents_.erase(it);
}

std::vector<PlaceCandidate> KeyFrameDatabase::Query(const cv::Mat& descriptors,
                                                    size_t max_candidates,
                                                    const std::set<uint64_t>& exclude) const {
  const auto bag = BagOfWords(descriptors);
  std::lock_guard<std::mutex> lock(mutex_);
  const double n = static_cast<double>(documents_.size());
  if (bag.empty() || documents_.empty() || max_candidates == 0) return {};
  const size_t max_df =
      std::max<size_t>(1, static_cast<size_t>(options_.max_word_frequency * n));
  // TF-IDF histogram intersection: sum over shared words of idf * min(count_q, count_kf),
  // normalised by the geometric mean of the two descriptor counts. Accumulated in word order
  // so the floating sums are the same on every run.
  std::unordered_map<uint64_t, double> scores;
  for (const auto& [word, count] : bag) {
    const auto it = inverted_.find(word);
    if (it == inverted_.end()) continue;
    const auto& list = it->second;
    if (list.size() > max_df && documents_.size() > 1) continue;  // stop word
    const double idf = std::log(n / static_cast<double>(list.size())) + 1e-3;
    for (const Entry& e : list) {
      scores[e.keyframe_id] += idf * static_cast<double>(std::min(count, e.count));
    }
  }
  const double query_length = static_cast<double>(descriptors.rows);
  const double max_idf = std::log(n) + 1e-3;
  std::vector<PlaceCandidate> result;
  result.reserve(scores.size());
  for (const auto& [id, raw] : scores) {
    if (exclude.count(id) > 0) continue;
    const Document& doc = documents_.at(id);
    // Normalised so a keyframe queried with its own descriptors and unique words scores 1.
    const double norm = max_idf * static_cast<double>(options_.num_tables) *
                        std::sqrt(query_length * doc.length);
    result.push_back({id, norm > 0 ? std::min(1.0, raw / norm) : 0.0});
  }
  std::sort(result.begin(), result.end(), [](const PlaceCandidate& a, const PlaceCandidate& b) {
    return a.score != b.score ? a.score > b.score : a.keyframe_id < b.keyframe_id;
  });
  if (result.size() > max_candidates) result.resize(max_candidates);
  return result;
}

size_t KeyFrameDatabase::Size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return documents_.size();
}

bool KeyFrameDatabase::Contains(uint64_t keyframe_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return documents_.count(keyframe_id) > 0;
}

}  // namespace ademono
