// Support for the face-orientation tests: a model written with its faces the other way round, as
// a user's file may have them.
#pragma once

#include <algorithm>
#include <random>
#include <vector>

#include "models/cao_reader.h"

namespace linetrack::test_support {

// `cao` with the point order of every face reversed when `share` is 1, else of a random subset
// (each face with probability `share`, drawn from `seed`).
inline CaoModel ReversedFaces(CaoModel cao, double share, unsigned seed) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution pick(share);
  for (std::vector<int>& face : cao.faces) {
    if (share >= 1.0 || pick(rng)) std::reverse(face.begin(), face.end());
  }
  return cao;
}

}  // namespace linetrack::test_support
