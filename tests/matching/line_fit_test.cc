// The line-fit model of the verification (matching/line_fit.h) on exact and noisy projections of
// the hall: zero residuals at the truth, the chi-square of Table 1 noise distributed as chi2(2),
// clutter mostly outside the gates, the cap above every ratio, fragments of one line collinear.
#include "matching/line_fit.h"

#include <gtest/gtest.h>

#include <random>

#include "scene_fixture.h"

namespace linetrack {
namespace {

constexpr double kExactTol = 1e-9;
constexpr int kViews = 60;
// chi2(2): mean 2, 99.9 % below 13.8. Over ~500 noisy pairs the mean lies within 0.3 of 2 and
// at most 1 % exceed the gate (measured: mean 2.05, 0.2 %).
constexpr double kMeanChi2Tol = 0.3;
constexpr double kMaxTrueOutsideGate = 0.01;
// Random clutter segments near a projected edge (within 100 px of its middle) rarely pass the
// gates (measured 0.04 %).
constexpr double kMaxClutterInsideGate = 0.01;

// Table 1 noise as the synthetic scenes apply it: the projected piece rotated about its middle
// by N(0, 1 deg), shifted along its normal by N(0, 3 px).
Segment2 Perturb(const Segment2& s, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const double angle = DegToRad(1.0) * normal(rng), offset = 3.0 * normal(rng);
  const Eigen::Vector2d mid = s.Mid();
  const Eigen::Rotation2Dd r(angle);
  const Eigen::Vector2d a = mid + r * (s.a - mid), b = mid + r * (s.b - mid);
  const Eigen::Vector2d d = (b - a).normalized(), n(-d.y(), d.x());
  return {a + offset * n, b + offset * n};
}

TEST(LineFit, ExactProjectionFitsPerfectlyAndReachesTheCap) {
  testing::HallFixture hall;
  std::mt19937_64 rng(21);
  const LineFitModel model;
  for (int v = 0; v < kViews; ++v) {
    for (const ProjectedEdge& p : hall.RandomView(rng).pieces) {
      const LineFit fit = FitLine(p.image, p.image, Eigen::Matrix2d::Zero(), model);
      EXPECT_NEAR(fit.residuals.norm(), 0.0, kExactTol);
      EXPECT_NEAR(fit.chi2, 0.0, kExactTol);
      EXPECT_NEAR(fit.overhang_px, 0.0, kExactTol);
      EXPECT_TRUE(fit.gated);
      EXPECT_NEAR(fit.log_likelihood_ratio, MaxLogLikelihoodRatio(p.image.Length(), model), 1e-9);
    }
  }
}

TEST(LineFit, TableOneNoiseGivesChiSquareWithTwoDegreesOfFreedom) {
  testing::HallFixture hall;
  std::mt19937_64 rng(22);
  const LineFitModel model;
  double sum = 0.0;
  int n = 0, outside = 0;
  for (int v = 0; v < kViews; ++v) {
    for (const ProjectedEdge& p : hall.RandomView(rng).pieces) {
      const LineFit fit = FitLine(p.image, Perturb(p.image, rng), Eigen::Matrix2d::Zero(), model);
      sum += fit.chi2;
      outside += fit.chi2 > model.gate_chi2 ? 1 : 0;
      ++n;
      // Never above the cap of its length.
      EXPECT_LE(fit.log_likelihood_ratio, MaxLogLikelihoodRatio(p.image.Length(), model) + 1e-6);
    }
  }
  ASSERT_GT(n, 300);
  RecordProperty("mean_chi2", std::to_string(sum / n));
  RecordProperty("outside_gate", std::to_string(static_cast<double>(outside) / n));
  RecordProperty("pairs", n);
  EXPECT_NEAR(sum / n, 2.0, kMeanChi2Tol);
  EXPECT_LE(static_cast<double>(outside) / n, kMaxTrueOutsideGate);
}

TEST(LineFit, ClutterNearAnEdgeIsMostlyOutsideTheGates) {
  testing::HallFixture hall;
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const LineFitModel model;
  int inside = 0, n = 0;
  for (int v = 0; v < kViews; ++v) {
    for (const ProjectedEdge& p : hall.RandomView(rng).pieces) {
      for (int k = 0; k < 5; ++k) {
        const Eigen::Vector2d mid = p.image.Mid() + 100.0 * Eigen::Vector2d(unit(rng), unit(rng));
        const double angle = kPi * unit(rng), half = 20.0 + 80.0 * (unit(rng) + 1.0);
        const Eigen::Vector2d d(std::cos(angle), std::sin(angle));
        const LineFit fit =
            FitLine(p.image, {mid - half * d, mid + half * d}, Eigen::Matrix2d::Zero(), model);
        inside += fit.gated ? 1 : 0;
        ++n;
      }
    }
  }
  RecordProperty("clutter_inside_gate", std::to_string(static_cast<double>(inside) / n));
  EXPECT_LE(static_cast<double>(inside) / n, kMaxClutterInsideGate);
}

TEST(LineFit, OverhangBeyondTheProjectionLeavesTheGate) {
  const LineFitModel model;
  const Segment2 projected{{100.0, 200.0}, {400.0, 200.0}};
  // Shorter than the projection: inside; longer by 30 px (10 sigma_d): outside.
  EXPECT_TRUE(
      FitLine(projected, {{120.0, 201.0}, {380.0, 199.0}}, Eigen::Matrix2d::Zero(), model).gated);
  const LineFit longer =
      FitLine(projected, {{70.0, 200.0}, {400.0, 200.0}}, Eigen::Matrix2d::Zero(), model);
  EXPECT_NEAR(longer.overhang_px, 30.0, 1e-9);
  EXPECT_FALSE(longer.gated);
  // The pose uncertainty of the projection's start lets it through.
  EXPECT_TRUE(FitLine(projected, {{70.0, 200.0}, {400.0, 200.0}}, Eigen::Matrix2d::Zero(), model,
                      {20.0 * 20.0, 0.0})
                  .gated);
}

TEST(LineFit, FragmentsOfOneLineAreCollinear) {
  const Segment2 line{{0.0, 0.0}, {300.0, 30.0}};
  const Eigen::Vector2d d = (line.b - line.a) / line.Length(), n(-d.y(), d.x());
  const Segment2 first{line.a, line.a + 120.0 * d};
  const Segment2 second{line.a + 160.0 * d, line.b};
  EXPECT_NEAR(FragmentChiSquare(first, second, 1.0), 0.0, kExactTol);
  // Offset by 8 px: not one line (the reference extrapolated 1.5 lengths has sigma ~2.7 px).
  EXPECT_GT(FragmentChiSquare(first, {second.a + 8.0 * n, second.b + 8.0 * n}, 1.0), 13.8);
  // Within the endpoint noise: one line.
  EXPECT_LT(FragmentChiSquare(first, {second.a + 0.5 * n, second.b - 0.5 * n}, 1.0), 13.8);
}

TEST(LineFit, EndpointDensityIsAHalfNormalAtTheEndPlusUniformCuts) {
  constexpr double kLength = 200.0, kSigma = 10.0, kEnd = 0.8;
  // Integrated over the piece it is end_probability (half-normal, sigma << length) + the cuts.
  double mass = 0.0;
  const int steps = 20000;
  for (int i = 0; i < steps; ++i) {
    mass +=
        EndpointAlongDensity((i + 0.5) * kLength / steps, kLength, kSigma, kEnd) * kLength / steps;
  }
  EXPECT_NEAR(mass, 1.0, 1e-3);
  EXPECT_GT(EndpointAlongDensity(0.0, kLength, kSigma, kEnd),
            EndpointAlongDensity(100.0, kLength, kSigma, kEnd));
}

}  // namespace
}  // namespace linetrack
