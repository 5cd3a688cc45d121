// Eq. 9 and eq. 10 on cases computed by hand.
#include "matching/segment_distance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace linetrack {
namespace {

constexpr double kTol = 1e-9;

Segment2 S(double ax, double ay, double bx, double by) {
  return {{ax, ay}, {bx, by}};
}

TEST(SegmentDistance, ParallelOffsetIsTheOffset) {
  EXPECT_NEAR(SegmentDistance(S(0, 0, 10, 0), S(2, 3, 8, 3)), 3.0, kTol);
}

TEST(SegmentDistance, IdenticalSegmentsAreAtZero) {
  EXPECT_NEAR(SegmentDistance(S(1, 2, 30, -4), S(1, 2, 30, -4)), 0.0, kTol);
}

TEST(SegmentDistance, CrossingSegmentAveragesTheAbsoluteOffset) {
  // Observed from (5, -2) to (5, 2) across a horizontal projected segment: mean |y| = 1.
  EXPECT_NEAR(SegmentDistance(S(0, 0, 10, 0), S(5, -2, 5, 2)), 1.0, kTol);
}

TEST(SegmentDistance, PartBeyondTheEndUsesTheEndPoint) {
  // Observed on the line y = 0 from x = 10 to x = 14, projected ends at x = 10: mean x - 10 = 2.
  EXPECT_NEAR(SegmentDistance(S(0, 0, 10, 0), S(10, 0, 14, 0)), 2.0, kTol);
  // Observed from (12, 1) to (12, 1 + 0): a point at distance sqrt(4 + 1).
  EXPECT_NEAR(SegmentDistance(S(0, 0, 10, 0), S(12, 1, 12, 1)), std::sqrt(5.0), kTol);
}

TEST(SegmentDistance, MatchesNumericalIntegration) {
  const Segment2 projected = S(3, 1, 40, 12), observed = S(-5, 8, 55, 2);
  const int n = 200000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d m = observed.a + (i + 0.5) / n * (observed.b - observed.a);
    const Eigen::Vector2d d = projected.b - projected.a;
    const double t = std::clamp((m - projected.a).dot(d) / d.squaredNorm(), 0.0, 1.0);
    sum += (m - (projected.a + t * d)).norm();
  }
  EXPECT_NEAR(SegmentDistance(projected, observed), sum / n, 1e-6);
}

TEST(PartialHausdorff, IsTheKthSmallest) {
  EXPECT_DOUBLE_EQ(PartialHausdorff({5.0, 1.0, 3.0, 9.0}, 3), 5.0);
  EXPECT_DOUBLE_EQ(PartialHausdorff({5.0, 1.0}, 1), 1.0);
  EXPECT_EQ(PartialHausdorff({5.0, 1.0}, 3), std::numeric_limits<double>::infinity());
}

}  // namespace
}  // namespace linetrack
