// Order statistics of samples (timings, errors, intensities). With the n values sorted ascending,
// x_0 <= ... <= x_{n-1}, a q-quantile (q clamped to [0, 1]) is the value of one rank k, never an
// interpolation between two:
//   nearest rank  k = floor(q (n - 1) + 1/2)   (q (n - 1) rounded half up; q = 1/2 gives n / 2)
//   lower rank    k = floor(q (n - 1))
// The functions take their values by copy (any random-access container of numbers) and select
// the rank with std::nth_element, which gives the same value as a full sort.
#pragma once

#include <algorithm>
#include <cstddef>
#include <utility>

namespace linetrack {

// The value of 0-based rank k of `values` in ascending order (k < size).
template <class Values>
double ValueOfRank(Values values, std::size_t k) {
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return static_cast<double>(values[k]);
}

// The q-quantile by nearest rank, k = floor(q (n - 1) + 1/2); 0 for no values. At q = 1/2 this
// is the upper median x_{n/2} (integer division).
template <class Values>
double QuantileNearestRank(Values values, double q) {
  if (values.empty()) return 0.0;
  const std::size_t last = values.size() - 1;
  const double rank = std::clamp(q, 0.0, 1.0) * static_cast<double>(last) + 0.5;
  return ValueOfRank(std::move(values), std::min(last, static_cast<std::size_t>(rank)));
}

// The q-quantile by lower rank, k = floor(q (n - 1)); 0 for no values.
template <class Values>
double QuantileLowerRank(Values values, double q) {
  if (values.empty()) return 0.0;
  const std::size_t last = values.size() - 1;
  const double rank = std::clamp(q, 0.0, 1.0) * static_cast<double>(last);
  return ValueOfRank(std::move(values), std::min(last, static_cast<std::size_t>(rank)));
}

// The median: the middle value for an odd count, the mean (x_{n/2-1} + x_{n/2}) / 2 of the two
// middle values for an even count; 0 for no values.
template <class Values>
double Median(Values values) {
  const std::size_t n = values.size();
  if (n == 0) return 0.0;
  std::sort(values.begin(), values.end());
  if (n % 2 == 1) return static_cast<double>(values[n / 2]);
  return 0.5 * (static_cast<double>(values[n / 2 - 1]) + static_cast<double>(values[n / 2]));
}

}  // namespace linetrack
