// Tokens (seed 002, section 4): the parameters of a neighbour in a segment's frame are
// invariant to the image's rotation, scale and translation; equalisation maps into the unit
// hypercube; a token is most likely under its own view's token.
#include "matching/views/tokens.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

namespace linetrack {
namespace {

constexpr double kExactTol = 1e-9;

Segment2 Similar(const Segment2& s, double angle, double scale, const Eigen::Vector2d& shift) {
  const Eigen::Matrix2d r = Eigen::Rotation2Dd(angle).toRotationMatrix();
  return {scale * r * s.a + shift, scale * r * s.b + shift};
}

std::vector<Segment2> RandomSegments(int n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 640.0), v(0.0, 480.0), a(-kPi, kPi), l(30.0, 150.0);
  std::vector<Segment2> out;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d mid(u(rng), v(rng));
    const double angle = a(rng), length = l(rng);
    const Eigen::Vector2d d(std::cos(angle), std::sin(angle));
    out.push_back({mid - 0.5 * length * d, mid + 0.5 * length * d});
  }
  return out;
}

TEST(Tokens, NeighbourParametersAreSimilarityInvariant) {
  const Segment2 p{{100.0, 100.0}, {200.0, 120.0}};
  const Segment2 q{{150.0, 160.0}, {170.0, 240.0}};
  const Eigen::Vector4d raw = NeighbourParameters(p, q);
  const Eigen::Vector2d shift(-40.0, 75.0);
  const Eigen::Vector4d moved =
      NeighbourParameters(Similar(p, 0.7, 1.8, shift), Similar(q, 0.7, 1.8, shift));
  EXPECT_LT((raw - moved).norm(), kExactTol);
  // Q's endpoint order does not matter; reversing P negates the midpoint coordinates.
  EXPECT_LT((NeighbourParameters(p, {q.b, q.a}) - raw).norm(), kExactTol);
  const Eigen::Vector4d reversed = NeighbourParameters({p.b, p.a}, q);
  EXPECT_NEAR(reversed[0], -raw[0], kExactTol);
  EXPECT_NEAR(reversed[1], -raw[1], kExactTol);
  EXPECT_NEAR(reversed[2], raw[2], kExactTol);
  EXPECT_NEAR(reversed[3], raw[3], kExactTol);
  // P itself at its own frame: midpoint at the origin, unit length, angle 0.
  EXPECT_LT(NeighbourParameters(p, p).norm(), kExactTol);
}

TEST(Tokens, SegmentGapIsZeroForCrossingSegments) {
  EXPECT_NEAR(SegmentGap({{0, 0}, {10, 0}}, {{5, -5}, {5, 5}}), 0.0, kExactTol);
  EXPECT_NEAR(SegmentGap({{0, 0}, {10, 0}}, {{12, 3}, {12, 10}}), std::hypot(2.0, 3.0), kExactTol);
}

TEST(Tokens, EqualisationMapsIntoTheUnitHypercubeMonotonically) {
  std::mt19937_64 rng(4);
  const std::vector<Segment2> segments = RandomSegments(60, rng);
  TokenOptions options;
  const std::vector<Eigen::Vector4d> sample = NeighbourSample(segments, options);
  const TokenEqualisation eq = TokenEqualisation::Fit(sample);
  ASSERT_FALSE(eq.Empty());
  double previous = -1.0;
  std::vector<Eigen::Vector4d> sorted = sample;
  std::sort(sorted.begin(), sorted.end(),
            [](const Eigen::Vector4d& a, const Eigen::Vector4d& b) { return a[0] < b[0]; });
  for (const Eigen::Vector4d& s : sorted) {
    const Eigen::Vector4d e = eq.Apply(s);
    EXPECT_GE(e.minCoeff(), 0.0);
    EXPECT_LE(e.maxCoeff(), 1.0);
    EXPECT_GE(e[0], previous);
    previous = e[0];
  }
  // About a tenth of the sample below the tenth percentile.
  int below = 0;
  for (const Eigen::Vector4d& s : sample)
    below += eq.Apply(s)[1] < 0.1;
  EXPECT_NEAR(static_cast<double>(below) / sample.size(), 0.1, 0.03);
}

TEST(Tokens, ATokenMatchesItsOwnSegmentBestUnderASimilarity) {
  std::mt19937_64 rng(5);
  const std::vector<Segment2> segments = RandomSegments(40, rng);
  TokenOptions options;
  const TokenEqualisation eq = TokenEqualisation::Fit(NeighbourSample(segments, options));
  std::vector<Segment2> moved;
  for (const Segment2& s : segments)
    moved.push_back(Similar(s, 0.3, 1.2, {20.0, -10.0}));
  const std::vector<Token> stored = ComputeTokens(segments, eq, options);
  const std::vector<Token> observed = ComputeTokens(moved, eq, options);
  ASSERT_EQ(stored.size(), observed.size());
  int best_is_own = 0;
  for (size_t t = 0; t < stored.size(); ++t) {
    size_t best = 0;
    double best_llr = -1e300;
    for (size_t p = 0; p < observed.size(); ++p) {
      const double llr = TokenLogLikelihoodRatio(stored[t], observed[p], options);
      if (llr > best_llr) {
        best_llr = llr;
        best = p;
      }
    }
    best_is_own += best == t;
    EXPECT_GT(TokenLogLikelihoodRatio(stored[t], observed[t], options), 0.0);
  }
  EXPECT_EQ(best_is_own, static_cast<int>(stored.size()));
}

TEST(Tokens, OptionsAreChecked) {
  TokenOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why));
  options.sigma = 0.0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_FALSE(why.empty());
}

}  // namespace
}  // namespace linetrack
