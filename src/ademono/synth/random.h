#pragma once
// Deterministic random numbers for scene generation. std:: distributions differ between standard
// libraries, so values are derived from the raw SplitMix64 output only; no global state.

#include <cstdint>

namespace ademono::synth {

// SplitMix64 finaliser: a good 64-bit mix of `x`, also used to derive sub-seeds.
inline uint64_t Mix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Seed for a named sub-stream, so adding draws to one part of a scene leaves others unchanged.
inline uint64_t SubSeed(uint64_t seed, uint64_t stream) { return Mix64(seed ^ Mix64(stream)); }

class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t Next() {
    state_ += 0x9E3779B97F4A7C15ull;
    uint64_t z = state_;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Integer in [lo, hi] (inclusive).
  int UniformInt(int lo, int hi) {
    return lo + static_cast<int>(Next() % static_cast<uint64_t>(hi - lo + 1));
  }

 private:
  uint64_t state_;
};

}  // namespace ademono::synth
