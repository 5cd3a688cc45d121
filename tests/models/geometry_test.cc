// Pure geometry of models/geometry.h on hand-computed cases.
#include "models/geometry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace linetrack {
namespace {

TEST(ImageGeometry, ClipKeepsThePartInsideTheImage) {
  Segment2 s{{-100.0, 240.0}, {800.0, 240.0}};
  ASSERT_TRUE(ClipSegmentToImage(640, 480, &s));
  EXPECT_NEAR(s.a.x(), 0.0, 1e-9);
  EXPECT_NEAR(s.b.x(), 639.0, 1e-9);
  Segment2 outside{{-10.0, -10.0}, {-1.0, 500.0}};
  EXPECT_FALSE(ClipSegmentToImage(640, 480, &outside));
  Segment2 diagonal{{-50.0, -50.0}, {50.0, 50.0}};
  ASSERT_TRUE(ClipSegmentToImage(640, 480, &diagonal));
  EXPECT_LT(diagonal.a.norm(), 1e-9);
}

// Bearings in [0, 2 pi) compare within this (radians): the rounding of atan2 and of 1 - x / l1.
constexpr double kBearingTolRad = 1e-14;

TEST(DiamondAngle, ExactOnTheAxesAndDiagonals) {
  EXPECT_EQ(DiamondAngle(1.0, 0.0), 0.0);
  EXPECT_EQ(DiamondAngle(2.0, 2.0), 0.5);
  EXPECT_EQ(DiamondAngle(0.0, 3.0), 1.0);
  EXPECT_EQ(DiamondAngle(-1.0, 1.0), 1.5);
  EXPECT_EQ(DiamondAngle(-4.0, 0.0), 2.0);
  EXPECT_EQ(DiamondAngle(-1.0, -1.0), 2.5);
  EXPECT_EQ(DiamondAngle(0.0, -0.5), 3.0);
  EXPECT_EQ(DiamondAngle(1.0, -1.0), 3.5);
  EXPECT_EQ(DiamondAngle(0.0, 0.0), 0.0);
  // Just below +x: just below 4, or 0 when 1 - x / l1 rounds to 0.
  EXPECT_GT(DiamondAngle(1.0, -1e-9), 3.999999);
  EXPECT_LT(DiamondAngle(1.0, -1e-9), 4.0);
  EXPECT_EQ(DiamondAngle(1.0, -1e-300), 0.0);
}

// The diamond angle orders directions as their bearings in [0, 2 pi), opposite directions differ
// by 2, and DiamondToBearing inverts it.
TEST(DiamondAngle, MonotoneInTheBearingAndInvertible) {
  std::mt19937 rng(17u);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<std::pair<double, double>> bearing_diamond;
  for (int k = 0; k < 20000; ++k) {
    const double scale = std::pow(10.0, 3.0 * unit(rng));
    const Eigen::Vector2d v = scale * Eigen::Vector2d(unit(rng), unit(rng));
    double b = std::atan2(v.y(), v.x());
    if (b < 0.0) b += 2.0 * kPi;
    const double d = DiamondAngle(v);
    ASSERT_GE(d, 0.0);
    ASSERT_LT(d, 4.0);
    EXPECT_NEAR(std::abs(WrapDiamond(DiamondAngle(-v) - d) - 2.0), 0.0, 1e-15);
    const double back = DiamondToBearing(d);
    EXPECT_NEAR(std::abs(WrapAngle(back - b)), 0.0, kBearingTolRad) << v.transpose();
    EXPECT_NEAR(std::abs(WrapDiamond(BearingToDiamond(b) - d + 2.0) - 2.0), 0.0, 1e-14);
    bearing_diamond.emplace_back(b, d);
  }
  std::sort(bearing_diamond.begin(), bearing_diamond.end());
  for (size_t k = 1; k < bearing_diamond.size(); ++k) {
    if (bearing_diamond[k].first - bearing_diamond[k - 1].first > kBearingTolRad) {
      EXPECT_GT(bearing_diamond[k].second, bearing_diamond[k - 1].second) << k;
    }
  }
}

TEST(DiamondAngle, WrapsModuloFour) {
  EXPECT_EQ(WrapDiamond(0.0), 0.0);
  EXPECT_EQ(WrapDiamond(4.0), 0.0);
  EXPECT_EQ(WrapDiamond(-1.0), 3.0);
  EXPECT_EQ(WrapDiamond(9.5), 1.5);
  EXPECT_EQ(WrapDiamond(-10.5), 1.5);
  EXPECT_EQ(WrapDiamond(-1e-20), 0.0);  // 4 - 1e-20 rounds to 4
  EXPECT_LT(WrapDiamond(-1e-15), 4.0);
}

// DiamondArcsMeet answers as the same arcs taken in radians, sampled densely.
TEST(DiamondAngle, ArcsMeetAsTheirBearings) {
  std::mt19937 rng(23u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int met = 0;
  for (int trial = 0; trial < 5000; ++trial) {
    const double a = 2.0 * kPi * unit(rng), a_width = 3.0 * unit(rng);
    const double b = 2.0 * kPi * unit(rng), b_width = 3.0 * unit(rng);
    const double da = BearingToDiamond(a), db = BearingToDiamond(b);
    const bool meet = DiamondArcsMeet(da, WrapDiamond(BearingToDiamond(a + a_width) - da), db,
                                      WrapDiamond(BearingToDiamond(b + b_width) - db), 1e-12);
    // In radians: one arc holds the other's start.
    const auto from = [](double x, double y) {
      const double d = y - x;
      return d - 2.0 * kPi * std::floor(d / (2.0 * kPi));
    };
    const bool expected = from(a, b) <= a_width || from(b, a) <= b_width;
    // Arcs within rounding of touching may go either way.
    const double gap = std::min(std::abs(from(a, b) - a_width), std::abs(from(b, a) - b_width));
    if (gap > 1e-9) {
      EXPECT_EQ(meet, expected) << "trial " << trial;
    }
    met += meet ? 1 : 0;
  }
  EXPECT_GT(met, 1000);  // both outcomes are exercised
  EXPECT_LT(met, 4900);
  // Touching arcs meet.
  EXPECT_TRUE(DiamondArcsMeet(0.5, 0.5, 1.0, 0.2, 0.0));
  EXPECT_TRUE(DiamondArcsMeet(3.5, 0.6, 0.05, 0.1, 0.0));  // across 4 = 0
  EXPECT_FALSE(DiamondArcsMeet(3.5, 0.4, 0.05, 0.1, 1e-12));
}

}  // namespace
}  // namespace linetrack
