#pragma once
// Place recognition over the map's own keyframes, with no downloaded vocabulary: a binary bag of
// words whose words are bit-sampling hashes of the ORB descriptors (locality-sensitive hashing:
// `num_tables` tables, each keyed by `bits_per_table` fixed bits of the 256), an inverted index
// word -> keyframes, and TF-IDF scoring with document frequencies of the current database. It
// needs no training, grows incrementally, and the same input gives the same candidates (the bit
// choice is a fixed function of `seed`; ties break by keyframe id). docs/maps.md compares it with
// FLANN LSH voting and brute-force voting.
//
// Thread-safe: every method locks an internal mutex.

#include <cstdint>
#include <map>
#include <mutex>
#include <set>
#include <unordered_map>
#include <vector>

#include <opencv2/core.hpp>

#include "ademono/core/options_table.h"

namespace ademono {

struct PlaceCandidate {
  uint64_t keyframe_id;
  double score;
};

struct KeyFrameDatabaseOptions {
  int num_tables = 4;        // hash tables (words per descriptor)
  int bits_per_table = 14;   // bits per word key: 2^bits words per table
  int seed = 1;              // which bits each table samples
  // Words in more than this fraction of the keyframes are stop words (skipped by queries).
  double max_word_frequency = 0.5;

  static const OptionsTable<KeyFrameDatabaseOptions>& Table();
  static KeyFrameDatabaseOptions FromYaml(const YAML::Node& node);
  YAML::Node ToYaml() const;
  void Check() const;
  bool operator==(const KeyFrameDatabaseOptions&) const = default;
};

class KeyFrameDatabase {
 public:
  explicit KeyFrameDatabase(const KeyFrameDatabaseOptions& options = {});

  // `descriptors`: CV_8U, one 32-byte ORB descriptor per row. Re-adding an id replaces it.
  void Add(uint64_t keyframe_id, const cv::Mat& descriptors);
  void Erase(uint64_t keyframe_id);
  // Best candidates by score, highest first (ties by id); `exclude` are ids never returned
  // (e.g. covisible keyframes). Scores are in [0, 1].
  std::vector<PlaceCandidate> Query(const cv::Mat& descriptors, size_t max_candidates,
                                    const std::set<uint64_t>& exclude = {}) const;
  size_t Size() const;
  bool Contains(uint64_t keyframe_id) const;
  const KeyFrameDatabaseOptions& Options() const { return options_; }

  // The words of each descriptor row (num_tables per row, as word ids), for tests and tools.
  std::vector<uint32_t> Words(const cv::Mat& descriptors) const;

 private:
  struct Entry {
    uint64_t keyframe_id;
    uint32_t count;
  };
  struct Document {
    std::vector<std::pair<uint32_t, uint32_t>> words;  // (word, count), by word
    double length = 0;                                  // number of descriptors
  };
  // (word, count) of a descriptor set, sorted by word.
  std::vector<std::pair<uint32_t, uint32_t>> BagOfWords(const cv::Mat& descriptors) const;
  void EraseLocked(uint64_t keyframe_id);

  KeyFrameDatabaseOptions options_;
  // For each table, (byte, mask) of each sampled bit.
  std::vector<std::vector<std::pair<int, uint8_t>>> bits_;
  mutable std::mutex mutex_;
  std::unordered_map<uint32_t, std::vector<Entry>> inverted_;  // word -> keyframes, by id
  std::map<uint64_t, Document> documents_;
};

}  // namespace ademono
