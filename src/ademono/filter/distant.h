#pragma once
// Distant-point filtering (filter 3): monocular depth far away is unreliable, so each point deeper
// than z_th is dropped with a fixed probability. The random source is the caller's seeded engine;
// the uniform draw is built from the engine's raw 64-bit output so results are bit-identical on
// every standard library (std::*_distribution are not).

#include <cstdint>
#include <random>
#include <vector>

namespace ademono {

// Uniform double in [0, 1) from the top 53 bits of a 64-bit word.
inline double UniformFromBits(uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

// True for points to drop: active, known depth (> 0, finite) above `z_th_m`, and a draw
// u < drop_probability. One engine draw per candidate point, in index order. `active` empty: all.
std::vector<bool> DrawDistantDrops(const std::vector<float>& depths,
                                   const std::vector<bool>& active, double z_th_m,
                                   double drop_probability, std::mt19937_64& rng);

}  // namespace ademono
