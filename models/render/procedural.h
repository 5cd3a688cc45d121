// Deterministic pseudo-random helpers for synthetic scenes: integer hashing, seeded uniform draws
// and smooth value noise. Everything here is a pure function of its inputs and a seed.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

namespace linetrack {

// SplitMix64 finaliser: a bijective 64-bit mix (Steele, Lea, Flood 2014).
inline uint64_t HashMix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Hash of two values (order matters).
inline uint64_t HashCombine(uint64_t a, uint64_t b) {
  return HashMix(a ^ (HashMix(b) + 0x632be59bd9b4e019ull));
}

// Uniform double in [0, 1) from a hash value (53 high bits).
inline double HashUnit(uint64_t h) {
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

// A stream of seeded uniform draws: the k-th draw is HashUnit(HashCombine(seed, k)), the same on
// every platform (unlike the std:: distributions).
class SeededDraws {
 public:
  explicit SeededDraws(uint64_t seed) : seed_(seed) {}

  double Unit() { return HashUnit(HashCombine(seed_, counter_++)); }  // [0, 1)
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Unit(); }
  int Index(int n) { return static_cast<int>(Unit() * n); }  // [0, n)
  // Standard normal draw (Box-Muller on two uniform draws).
  double Normal() {
    const double u1 = 1.0 - Unit(), u2 = Unit();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }

 private:
  uint64_t seed_;
  uint64_t counter_ = 0;
};

// Smooth 2D value noise with unit lattice spacing, values in [-1, 1]: random values on a
// periodic 256 x 256 lattice, interpolated bilinearly with smoothstep weights (C1).
class ValueNoise {
 public:
  explicit ValueNoise(uint64_t seed);

  // Noise at (s, t) in lattice units.
  float operator()(double s, double t) const;

 private:
  static constexpr int kSize = 256;
  std::vector<float> lattice_;
};

}  // namespace linetrack
