#include "models/render/procedural.h"

#include <cmath>

namespace linetrack {

ValueNoise::ValueNoise(uint64_t seed) : lattice_(kSize * kSize) {
  for (int i = 0; i < kSize * kSize; ++i) {
    lattice_[i] = static_cast<float>(2.0 * HashUnit(HashCombine(seed, i)) - 1.0);
  }
}

float ValueNoise::operator()(double s, double t) const {
  const double fs = std::floor(s), ft = std::floor(t);
  const float a = static_cast<float>(s - fs), b = static_cast<float>(t - ft);
  const int i0 = static_cast<int>(static_cast<int64_t>(fs) & (kSize - 1));
  const int j0 = static_cast<int>(static_cast<int64_t>(ft) & (kSize - 1));
  const int i1 = (i0 + 1) & (kSize - 1), j1 = (j0 + 1) & (kSize - 1);
  const float wa = a * a * (3.0f - 2.0f * a), wb = b * b * (3.0f - 2.0f * b);
  const float* row0 = &lattice_[j0 * kSize];
  const float* row1 = &lattice_[j1 * kSize];
  const float top = row0[i0] + wa * (row0[i1] - row0[i0]);
  const float bottom = row1[i0] + wa * (row1[i1] - row1[i0]);
  return top + wb * (bottom - top);
}

}  // namespace linetrack
