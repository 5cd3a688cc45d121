// Line-segment tokens after Wilkes, Dickinson, Rivlin and Basri (seed 002, section 4): each
// segment P is described by its k nearest neighbouring segments Q, expressed in P's own frame
// (origin at P's midpoint, P the unit x axis), each Q's parameters equalised into the unit
// hypercube; a stored token is matched to an image segment by the likelihood of eqs. 14-15.
// docs/views.md.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "models/geometry.h"

namespace linetrack {

struct TokenOptions {
  int neighbours = 6;           // k: neighbouring segments describing a segment
  double min_length_px = 20.0;  // shorter segments are neither tokens nor neighbours
  // Standard deviation of a neighbour's equalised parameters between views (unit hypercube).
  double sigma = 0.06;
  // p0 of eq. 14: the probability that an observed neighbour is none of the token's.
  double outlier_probability = 0.3;

  bool Check(std::string* why) const;
};

// Parameters of segment Q in the frame of segment P (eq. 14's feature vector): midpoint
// (x_c, y_c) in units of P's length with P running from (-1/2, 0) to (1/2, 0) and y turned
// +90 degrees from x in the image, ln(|Q| / |P|), and Q's angle to P modulo pi (radians). The
// seed's (dx, dy) become (length, angle) so that the order of Q's endpoints does not matter;
// reversing P maps (x_c, y_c) to (-x_c, -y_c).
Eigen::Vector4d NeighbourParameters(const Segment2& p, const Segment2& q);

// Distance (pixels) between two segments: the smallest distance between their points.
double SegmentGap(const Segment2& a, const Segment2& b);

// Indices of the k segments nearest to segments[i] (SegmentGap), among those at least
// min_length_px long, nearest first.
std::vector<int> NearestSegments(const std::vector<Segment2>& segments, int i,
                                 const TokenOptions& options);

// Histogram equalisation of the four parameters (seed 002: each parameter replaced by its
// percentile in a large sample): per dimension, the 101 percentiles of the sample; Apply maps a
// raw vector into [0, 1]^4 by the piecewise-linear cumulative distribution. The angle's table
// spans [0, pi] so that the map keeps its period.
struct TokenEqualisation {
  std::array<std::vector<double>, 4> percentiles;

  bool Empty() const { return percentiles[0].empty(); }
  Eigen::Vector4d Apply(const Eigen::Vector4d& raw) const;
  // From a sample of raw parameter vectors (at least 2).
  static TokenEqualisation Fit(const std::vector<Eigen::Vector4d>& sample);
};

// A segment's token: its neighbours' equalised parameters in its frame, for the segment in its
// stored direction (a -> b) and reversed.
struct Token {
  int segment = -1;
  std::array<std::vector<Eigen::Vector4d>, 2> neighbours;
};

// The raw parameters of every segment's neighbours (both directions), the sample for Fit.
std::vector<Eigen::Vector4d> NeighbourSample(const std::vector<Segment2>& segments,
                                             const TokenOptions& options);

// Tokens of the segments at least min_length_px long with at least one neighbour.
std::vector<Token> ComputeTokens(const std::vector<Segment2>& segments,
                                 const TokenEqualisation& equalisation,
                                 const TokenOptions& options);

// ln p(P | T) - ln p(P | outliers), eq. 15 against every neighbour being an outlier:
// sum over P's neighbours Q of ln(p0 + (1 - p0) / k_T sum_j N(Q; mu_j, sigma^2 I)), the angle
// dimension taken modulo 1. The better of P's two directions against T's stored direction.
double TokenLogLikelihoodRatio(const Token& stored, const Token& observed,
                               const TokenOptions& options);

}  // namespace linetrack
