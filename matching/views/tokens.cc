#include "matching/views/tokens.h"

#include <algorithm>
#include <cmath>

namespace linetrack {

bool TokenOptions::Check(std::string* why) const {
  if (neighbours < 1 || !(min_length_px >= 0.0) || !(sigma > 0.0 && sigma < 1.0) ||
      !(outlier_probability > 0.0 && outlier_probability < 1.0)) {
    *why =
        "token options: neighbours >= 1, min_length_px >= 0, sigma and outlier_probability in "
        "(0, 1)";
    return false;
  }
  return true;
}

Eigen::Vector4d NeighbourParameters(const Segment2& p, const Segment2& q) {
  const double length = p.Length();
  const Eigen::Vector2d e = (p.b - p.a) / length;
  const Eigen::Vector2d n(-e.y(), e.x());
  const Eigen::Vector2d c = q.Mid() - p.Mid();
  const Eigen::Vector2d d = q.b - q.a;
  double angle = std::atan2(d.dot(n), d.dot(e));
  angle = std::fmod(angle + kPi, kPi);  // [0, pi)
  return {c.dot(e) / length, c.dot(n) / length, std::log(q.Length() / length), angle};
}

namespace {

double PointToSegment(const Eigen::Vector2d& p, const Segment2& s) {
  const Eigen::Vector2d d = s.b - s.a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - s.a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (s.a + t * d - p).norm();
}

bool Intersect(const Segment2& a, const Segment2& b) {
  const Eigen::Vector2d r = a.b - a.a, s = b.b - b.a;
  const double denom = Cross2(r, s);
  if (denom == 0.0) return false;
  const double t = Cross2(b.a - a.a, s) / denom, u = Cross2(b.a - a.a, r) / denom;
  return t >= 0.0 && t <= 1.0 && u >= 0.0 && u <= 1.0;
}

// Squared distance in the unit hypercube with the angle (dimension 3) taken modulo 1.
double HypercubeDistance2(const Eigen::Vector4d& x, const Eigen::Vector4d& y) {
  Eigen::Vector4d d = x - y;
  d[3] = std::abs(d[3]);
  d[3] = std::min(d[3], 1.0 - d[3]);
  return d.squaredNorm();
}

}  // namespace

double SegmentGap(const Segment2& a, const Segment2& b) {
  if (Intersect(a, b)) return 0.0;
  return std::min({PointToSegment(a.a, b), PointToSegment(a.b, b), PointToSegment(b.a, a),
                   PointToSegment(b.b, a)});
}

std::vector<int> NearestSegments(const std::vector<Segment2>& segments, int i,
                                 const TokenOptions& options) {
  std::vector<std::pair<double, int>> by_distance;
  for (size_t j = 0; j < segments.size(); ++j) {
    if (static_cast<int>(j) == i || segments[j].Length() < options.min_length_px) continue;
    by_distance.emplace_back(SegmentGap(segments[i], segments[j]), static_cast<int>(j));
  }
  const size_t k = std::min(by_distance.size(), static_cast<size_t>(options.neighbours));
  std::partial_sort(by_distance.begin(), by_distance.begin() + k, by_distance.end());
  std::vector<int> out;
  for (size_t j = 0; j < k; ++j)
    out.push_back(by_distance[j].second);
  return out;
}

Eigen::Vector4d TokenEqualisation::Apply(const Eigen::Vector4d& raw) const {
  Eigen::Vector4d out;
  for (int d = 0; d < 4; ++d) {
    const std::vector<double>& table = percentiles[d];
    const int n = static_cast<int>(table.size());
    const auto above = std::upper_bound(table.begin(), table.end(), raw[d]);
    if (above == table.begin()) {
      out[d] = 0.0;
    } else if (above == table.end()) {
      out[d] = 1.0;
    } else {
      const int hi = static_cast<int>(above - table.begin());
      const double lo_value = table[hi - 1], hi_value = table[hi];
      const double frac = hi_value > lo_value ? (raw[d] - lo_value) / (hi_value - lo_value) : 0.5;
      out[d] = (hi - 1 + frac) / (n - 1);
    }
  }
  return out;
}

TokenEqualisation TokenEqualisation::Fit(const std::vector<Eigen::Vector4d>& sample) {
  TokenEqualisation eq;
  if (sample.size() < 2) return eq;
  for (int d = 0; d < 4; ++d) {
    std::vector<double> values;
    values.reserve(sample.size());
    for (const Eigen::Vector4d& v : sample)
      values.push_back(v[d]);
    std::sort(values.begin(), values.end());
    for (int p = 0; p <= 100; ++p) {
      eq.percentiles[d].push_back(values[static_cast<size_t>(p / 100.0 * (values.size() - 1))]);
    }
  }
  eq.percentiles[3].front() = 0.0;
  eq.percentiles[3].back() = kPi;
  return eq;
}

std::vector<Eigen::Vector4d> NeighbourSample(const std::vector<Segment2>& segments,
                                             const TokenOptions& options) {
  std::vector<Eigen::Vector4d> out;
  for (size_t i = 0; i < segments.size(); ++i) {
    if (segments[i].Length() < options.min_length_px) continue;
    for (int j : NearestSegments(segments, static_cast<int>(i), options)) {
      const Eigen::Vector4d q = NeighbourParameters(segments[i], segments[j]);
      out.push_back(q);
      out.push_back({-q[0], -q[1], q[2], q[3]});
    }
  }
  return out;
}

std::vector<Token> ComputeTokens(const std::vector<Segment2>& segments,
                                 const TokenEqualisation& equalisation,
                                 const TokenOptions& options) {
  std::vector<Token> out;
  for (size_t i = 0; i < segments.size(); ++i) {
    if (segments[i].Length() < options.min_length_px) continue;
    Token token;
    token.segment = static_cast<int>(i);
    for (int j : NearestSegments(segments, static_cast<int>(i), options)) {
      const Eigen::Vector4d q = NeighbourParameters(segments[i], segments[j]);
      token.neighbours[0].push_back(equalisation.Apply(q));
      token.neighbours[1].push_back(equalisation.Apply({-q[0], -q[1], q[2], q[3]}));
    }
    if (!token.neighbours[0].empty()) out.push_back(std::move(token));
  }
  return out;
}

double TokenLogLikelihoodRatio(const Token& stored, const Token& observed,
                               const TokenOptions& options) {
  const std::vector<Eigen::Vector4d>& mu = stored.neighbours[0];
  if (mu.empty()) return 0.0;
  const double s2 = options.sigma * options.sigma;
  const double norm = 1.0 / (4.0 * kPi * kPi * s2 * s2);  // (2 pi sigma^2)^-2 in 4 dimensions
  const double p0 = options.outlier_probability;
  const double pj = (1.0 - p0) / static_cast<double>(mu.size());
  const double cutoff = 36.0 * s2;  // beyond 6 sigma a density adds nothing
  double best = -1e300;
  for (const std::vector<Eigen::Vector4d>& qs : observed.neighbours) {
    double llr = 0.0;
    for (const Eigen::Vector4d& q : qs) {
      double mixture = 0.0;
      for (const Eigen::Vector4d& m : mu) {
        const double d2 = HypercubeDistance2(q, m);
        if (d2 < cutoff) mixture += std::exp(-0.5 * d2 / s2);
      }
      llr += std::log(p0 + pj * norm * mixture);
    }
    best = std::max(best, llr);
  }
  return best;
}

}  // namespace linetrack
