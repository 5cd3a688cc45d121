#include "matching/line_fit.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

namespace linetrack {

Eigen::Matrix2d EndpointNoiseCovariance(double t_a, double t_b, double sigma_d,
                                        double sigma_theta) {
  const double d2 = sigma_d * sigma_d, a2 = sigma_theta * sigma_theta;
  Eigen::Matrix2d c;
  c << d2 + a2 * t_a * t_a, d2 + a2 * t_a * t_b, d2 + a2 * t_a * t_b, d2 + a2 * t_b * t_b;
  return c;
}

double EndpointAlongDensity(double inward, double length, double sigma, double end_probability) {
  constexpr double kHalfNormal = 0.7978845608028654;  // sqrt(2 / pi)
  return end_probability * kHalfNormal / sigma *
             std::exp(-0.5 * inward * inward / (sigma * sigma)) +
         (1.0 - end_probability) / length;
}

double MaxLogLikelihoodRatio(double length, const LineFitModel& model) {
  const double d = model.image_diagonal_px;
  const double piece = std::max(length, 1.0);
  const double end_sigma =
      std::sqrt((model.end_shortening * piece) * (model.end_shortening * piece) +
                model.offset_px * model.offset_px);
  return std::log(d / (2.0 * model.offset_px * model.angle_rad)) +
         2.0 * std::log(d * EndpointAlongDensity(0.0, piece, end_sigma, model.end_probability));
}

double FragmentChiSquare(const Segment2& reference, const Segment2& fragment, double sigma) {
  const double length = reference.Length();
  if (length < 1e-9 || !(sigma > 0.0)) return std::numeric_limits<double>::infinity();
  const Eigen::Vector2d u = (reference.b - reference.a) / length, n(-u.y(), u.x());
  const Eigen::Vector2d mid = reference.Mid();
  const Eigen::Vector2d r(n.dot(fragment.a - mid), n.dot(fragment.b - mid));
  const double ta = u.dot(fragment.a - mid) / length, tb = u.dot(fragment.b - mid) / length;
  Eigen::Matrix2d c;
  c << 1.5 + 2.0 * ta * ta, 0.5 + 2.0 * ta * tb, 0.5 + 2.0 * ta * tb, 1.5 + 2.0 * tb * tb;
  return r.dot((sigma * sigma * c).inverse() * r);
}

LineFit FitLine(const Segment2& projected, const Segment2& observed,
                const Eigen::Matrix2d& pose_term, const LineFitModel& model,
                const Eigen::Vector2d& end_variance) {
  LineFit fit;
  const Eigen::Vector2d axis = projected.b - projected.a;
  const double lambda = axis.norm();
  const double length = observed.Length();
  if (lambda < 1e-9 || length < 1e-9) return fit;
  const Eigen::Vector2d u = axis / lambda, n(-u.y(), u.x());
  fit.residuals = {n.dot(observed.a - projected.a), n.dot(observed.b - projected.a)};
  const double s_a = u.dot(observed.a - projected.a), s_b = u.dot(observed.b - projected.a);
  fit.lo = std::min(s_a, s_b);
  fit.hi = std::max(s_a, s_b);
  fit.overhang_px = std::max({0.0, -fit.lo, fit.hi - lambda});
  // Levers from the middle of the projected piece: the rotation centre of the noise model.
  const double centre = 0.5 * lambda;
  fit.covariance =
      EndpointNoiseCovariance(s_a - centre, s_b - centre, model.offset_px, model.angle_rad) +
      pose_term;
  const double det = fit.covariance.determinant();
  if (!(det > 0.0)) return fit;
  fit.chi2 = fit.residuals.dot(fit.covariance.inverse() * fit.residuals);
  if (fit.chi2 > model.gate_chi2) return fit;  // outside the gate: no ratio needed
  // Position noise of the projection's ends along it: the line noise (sigma_d) and the pose.
  const double d2 = model.offset_px * model.offset_px;
  const double sigma_a = std::sqrt(d2 + end_variance.x()),
               sigma_b = std::sqrt(d2 + end_variance.y());
  const double end_sigma =
      std::sqrt((model.end_shortening * lambda) * (model.end_shortening * lambda) +
                (std::max(sigma_a, sigma_b)) * (std::max(sigma_a, sigma_b)));
  // The observed segment's start (lo) belongs to the projection's start, its end (hi) to its
  // end; the pose uncertainty of the end concerned.
  const double along =
      std::log(model.image_diagonal_px *
               EndpointAlongDensity(fit.lo, lambda, end_sigma, model.end_probability)) +
      std::log(model.image_diagonal_px *
               EndpointAlongDensity(lambda - fit.hi, lambda, end_sigma, model.end_probability));
  fit.log_likelihood_ratio =
      std::log(model.image_diagonal_px * length / (2.0 * std::sqrt(det))) - 0.5 * fit.chi2 + along;
  fit.gated = fit.chi2 <= model.gate_chi2 && -fit.lo <= model.extent_sigmas * sigma_a &&
              fit.hi - lambda <= model.extent_sigmas * sigma_b;
  return fit;
}

}  // namespace linetrack
