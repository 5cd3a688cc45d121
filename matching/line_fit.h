// How well an observed image segment fits a model edge projected at a pose, under the line noise
// model of the paper's Table 1: the segment is a piece of the edge's image, rotated about the
// middle of the projected piece by N(0, sigma_theta) and shifted along its normal by
// N(0, sigma_d); pieces may be shorter than the projection (occlusion, fragmentation), not
// longer. Clutter lines have offsets uniform over the image diagonal D and angles uniform over
// pi. See docs/matching.md for the derivation.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <limits>

#include "models/geometry.h"

namespace linetrack {

struct LineFitModel {
  double offset_px = 3.0;                   // sigma_d (pixels)
  double angle_rad = 0.017453292519943295;  // sigma_theta (radians)
  double image_diagonal_px = 800.0;         // D: range of the clutter offsets (pixels)
  // A pair is a candidate when its chi-square (2 dof) is below this (13.8: 99.9 %) and the
  // segment overhangs the projection by at most extent_sigmas standard deviations of an
  // endpoint's position.
  double gate_chi2 = 13.8;
  double extent_sigmas = 3.0;
  // Along the edge, the start (end) of an observed segment lies near the start (end) of the
  // projected piece with probability end_probability (shortened by a half-normal amount of
  // standard deviation end_shortening x the piece's length), else anywhere on it (a cut:
  // occlusion, fragmentation).
  double end_probability = 0.8;
  double end_shortening = 0.1;
};

struct LineFit {
  // Signed distances (pixels) of the observed endpoints to the projected edge's line, and their
  // covariance under the hypothesis "the segment is this edge's image" (noise and pose).
  Eigen::Vector2d residuals = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();
  double chi2 = std::numeric_limits<double>::infinity();
  // Span of the observed segment along the projected edge (pixels from its first endpoint), and
  // how far it reaches beyond the projection's ends (>= 0).
  double lo = 0.0, hi = 0.0;
  double overhang_px = 0.0;
  // ln p(segment | edge) - ln p(segment | clutter) (nats): across the line
  // ln(D L / (2 sqrt(det covariance))) - chi2 / 2 (L the observed length), plus along it
  // sum_k ln(D p(t_k)) for the endpoints' distances t_k in from their ends of the projection
  // (clutter endpoints uniform over D).
  double log_likelihood_ratio = -std::numeric_limits<double>::infinity();
  bool gated = false;  // chi2 and overhang within the model's gates
};

// True when the spans of two fits along one projected edge overlap by more than `tolerance`
// pixels (two lines cannot both be that stretch of the edge's image).
inline bool SpansOverlap(const LineFit& a, const LineFit& b, double tolerance) {
  return std::min(a.hi, b.hi) - std::max(a.lo, b.lo) > tolerance;
}

// Covariance of the two endpoint residuals for levers t_a, t_b (pixels along the line from the
// rotation centre): sigma_d^2 [1 1; 1 1] + sigma_theta^2 [t_a^2 t_a t_b; t_a t_b t_b^2].
Eigen::Matrix2d EndpointNoiseCovariance(double t_a, double t_b, double sigma_d, double sigma_theta);

// Density (1 / pixels) of an observed endpoint `inward` pixels in from its end of a projected
// piece of `length` pixels (negative: beyond it): end_probability HalfNormal(|inward|; sigma)
// (the end, shortened) + (1 - end_probability) / length (a cut anywhere along the piece).
double EndpointAlongDensity(double inward, double length, double sigma, double end_probability);

// The largest log-likelihood ratio (nats) a segment of `length` pixels can reach under `model`:
// chi2 = 0, no pose uncertainty, both endpoints at the ends of a piece of about its length.
double MaxLogLikelihoodRatio(double length, const LineFitModel& model);

// Chi-square (2 dof) of `fragment` lying on the line of `reference` when both are pieces of one
// detected line whose endpoints carry independent N(0, sigma) offsets: the reference's line is
// extrapolated (offset variance sigma^2 (1/2 + 2 t^2 / L^2) at t from its middle, L its length)
// and the fragment's endpoints add sigma^2 each.
double FragmentChiSquare(const Segment2& reference, const Segment2& fragment, double sigma);

// The fit of `observed` to `projected` (pixels). `pose_term` is the residual covariance the pose
// uncertainty adds (J C J^T, J = d residuals / d pose), zero for a known pose; `end_variance` the
// variance (pixels^2) the pose uncertainty gives the positions of projected.a and projected.b
// along the projection.
LineFit FitLine(const Segment2& projected, const Segment2& observed,
                const Eigen::Matrix2d& pose_term, const LineFitModel& model,
                const Eigen::Vector2d& end_variance = Eigen::Vector2d::Zero());

}  // namespace linetrack
