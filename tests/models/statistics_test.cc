// Quantile rules of models/statistics.h on hand-ranked samples.
#include "models/statistics.h"

#include <gtest/gtest.h>

#include <deque>
#include <random>
#include <vector>

namespace linetrack {
namespace {

// Odd count, unsorted: ranks 0..4 hold 1, 2, 3, 4, 5.
const std::vector<double> kFive = {5.0, 1.0, 4.0, 2.0, 3.0};
// Even count, unsorted: ranks 0..3 hold 1, 2, 3, 4.
const std::vector<double> kFour = {4.0, 1.0, 3.0, 2.0};

TEST(Statistics, NearestRankRoundsHalfUp) {
  // k = floor(q (n - 1) + 1/2), n = 5.
  EXPECT_EQ(QuantileNearestRank(kFive, 0.5), 3.0);   // 2.5 -> 2
  EXPECT_EQ(QuantileNearestRank(kFive, 0.6), 3.0);   // 2.9 -> 2
  EXPECT_EQ(QuantileNearestRank(kFive, 0.65), 4.0);  // 3.1 -> 3
  EXPECT_EQ(QuantileNearestRank(kFive, 0.9), 5.0);   // 4.1 -> 4
  EXPECT_EQ(QuantileNearestRank(kFive, 0.0), 1.0);
  EXPECT_EQ(QuantileNearestRank(kFive, 1.0), 5.0);
  // n = 4: q = 1/2 gives the upper of the two middle values (rank n / 2 = 2).
  EXPECT_EQ(QuantileNearestRank(kFour, 0.5), 3.0);  // 2.0 -> 2
  EXPECT_EQ(QuantileNearestRank(kFour, 0.3), 2.0);  // 1.4 -> 1
}

TEST(Statistics, LowerRankTruncates) {
  // k = floor(q (n - 1)).
  EXPECT_EQ(QuantileLowerRank(kFive, 0.9), 4.0);   // 3.6 -> 3
  EXPECT_EQ(QuantileLowerRank(kFive, 0.25), 2.0);  // 1.0 -> 1
  EXPECT_EQ(QuantileLowerRank(kFive, 1.0), 5.0);
  EXPECT_EQ(QuantileLowerRank(kFour, 0.5), 2.0);   // 1.5 -> 1
  EXPECT_EQ(QuantileLowerRank(kFour, 0.95), 3.0);  // 2.85 -> 2
}

TEST(Statistics, MedianAveragesTheTwoMiddleValuesOfAnEvenCount) {
  EXPECT_EQ(Median(kFive), 3.0);
  EXPECT_EQ(Median(kFour), 2.5);
  EXPECT_EQ(Median(std::vector<double>{7.0}), 7.0);
}

TEST(Statistics, OutOfRangeLevelsAreClampedAndEmptySamplesGiveZero) {
  EXPECT_EQ(QuantileNearestRank(kFive, -1.0), 1.0);
  EXPECT_EQ(QuantileNearestRank(kFive, 2.0), 5.0);
  EXPECT_EQ(QuantileLowerRank(kFive, 2.0), 5.0);
  EXPECT_EQ(QuantileNearestRank(std::vector<double>{}, 0.5), 0.0);
  EXPECT_EQ(QuantileLowerRank(std::vector<double>{}, 0.5), 0.0);
  EXPECT_EQ(Median(std::vector<double>{}), 0.0);
}

TEST(Statistics, SelectionMatchesAFullSortOnOtherContainers) {
  std::mt19937 engine(7);
  std::uniform_real_distribution<float> uniform(-10.0f, 10.0f);
  std::vector<float> values(101);
  for (float& v : values)
    v = uniform(engine);
  std::vector<float> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  const std::deque<float> queue(values.begin(), values.end());
  for (const double q : {0.0, 0.05, 0.5, 0.95, 0.99, 1.0}) {
    const size_t nearest = static_cast<size_t>(q * 100.0 + 0.5);
    const size_t lower = static_cast<size_t>(q * 100.0);
    EXPECT_EQ(QuantileNearestRank(values, q), static_cast<double>(sorted[nearest])) << q;
    EXPECT_EQ(QuantileNearestRank(queue, q), static_cast<double>(sorted[nearest])) << q;
    EXPECT_EQ(QuantileLowerRank(values, q), static_cast<double>(sorted[lower])) << q;
  }
}

}  // namespace
}  // namespace linetrack
