#include "matching/segment_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace linetrack {
namespace {

// Integral over t in [t0, t1] of sqrt(a t^2 + b t + c), a > 0, the quadratic being a squared
// distance (non-negative).
double IntegralOfSqrtQuadratic(double a, double b, double c, double t0, double t1) {
  const double k = std::max(c / a - b * b / (4.0 * a * a), 0.0);
  auto primitive = [&](double t) {
    const double u = t + b / (2.0 * a);
    const double root = std::sqrt(u * u + k);
    const double log_term = k > 0.0 ? k * std::asinh(u / std::sqrt(k)) : 0.0;
    return 0.5 * (u * root + log_term);
  };
  return std::sqrt(a) * (primitive(t1) - primitive(t0));
}

// Integral over t in [t0, t1] of |y0 + t dy|.
double IntegralOfAbsLinear(double y0, double dy, double t0, double t1) {
  auto f = [&](double t) { return y0 + t * dy; };
  if (std::abs(dy) > 0.0) {
    const double t_zero = -y0 / dy;
    if (t_zero > t0 && t_zero < t1) {
      return 0.5 * std::abs(f(t0)) * (t_zero - t0) + 0.5 * std::abs(f(t1)) * (t1 - t_zero);
    }
  }
  return 0.5 * (std::abs(f(t0)) + std::abs(f(t1))) * (t1 - t0);
}

}  // namespace

double SegmentDistance(const Segment2& projected, const Segment2& observed) {
  const Eigen::Vector2d axis = projected.b - projected.a;
  const double lambda = axis.norm();
  const Eigen::Vector2d d_obs = observed.b - observed.a;
  const double length = d_obs.norm();
  if (lambda < 1e-12) {  // a point: mean distance to it
    if (length < 1e-12) return (observed.a - projected.a).norm();
    const Eigen::Vector2d rel = observed.a - projected.a;
    return IntegralOfSqrtQuadratic(d_obs.squaredNorm(), 2.0 * rel.dot(d_obs), rel.squaredNorm(),
                                   0.0, 1.0);
  }
  if (length < 1e-12) {
    const Eigen::Vector2d x = axis / lambda;
    const double s = std::clamp((observed.a - projected.a).dot(x), 0.0, lambda);
    return (observed.a - (projected.a + s * x)).norm();
  }
  // Frame of the projected segment: x along it from its start, y across.
  const Eigen::Vector2d ex = axis / lambda, ey(-ex.y(), ex.x());
  const Eigen::Vector2d rel = observed.a - projected.a;
  const double x0 = rel.dot(ex), y0 = rel.dot(ey);
  const double dx = d_obs.dot(ex), dy = d_obs.dot(ey);
  // Breakpoints where the nearest point switches between start, interior and end.
  std::vector<double> cuts = {0.0, 1.0};
  if (std::abs(dx) > 0.0) {
    for (double xb : {0.0, lambda}) {
      const double t = (xb - x0) / dx;
      if (t > 0.0 && t < 1.0) cuts.push_back(t);
    }
  }
  std::sort(cuts.begin(), cuts.end());
  double total = 0.0;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double t0 = cuts[i], t1 = cuts[i + 1];
    const double xm = x0 + 0.5 * (t0 + t1) * dx;
    if (xm < 0.0 || xm > lambda) {  // distance to an end point
      const double ex0 = xm < 0.0 ? x0 : x0 - lambda;
      total += IntegralOfSqrtQuadratic(dx * dx + dy * dy, 2.0 * (ex0 * dx + y0 * dy),
                                       ex0 * ex0 + y0 * y0, t0, t1);
    } else {
      total += IntegralOfAbsLinear(y0, dy, t0, t1);
    }
  }
  return total;  // the parameter runs over [0, 1]: the integral is already the mean
}

double PartialHausdorff(std::vector<double> distances, int k) {
  if (k < 1 || static_cast<int>(distances.size()) < k) {
    return std::numeric_limits<double>::infinity();
  }
  std::nth_element(distances.begin(), distances.begin() + (k - 1), distances.end());
  return distances[k - 1];
}

}  // namespace linetrack
