#include "matching/lines/segment_fitting.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace linetrack {

Segment2 FitSegment(const std::vector<Eigen::Vector2d>& points) {
  Segment2 s;
  if (points.empty()) return s;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : points)
    centroid += p;
  centroid /= static_cast<double>(points.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& p : points) {
    const Eigen::Vector2d d = p - centroid;
    scatter += d * d.transpose();
  }
  if (scatter.trace() <= 0.0) {
    s.a = s.b = centroid;
    return s;
  }
  // Eigenvalues ascending: the last eigenvector is the direction of largest spread.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
  const Eigen::Vector2d direction = eigen.eigenvectors().col(1);
  double t_min = std::numeric_limits<double>::infinity(), t_max = -t_min;
  for (const Eigen::Vector2d& p : points) {
    const double t = (p - centroid).dot(direction);
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
  }
  s.a = centroid + t_min * direction;
  s.b = centroid + t_max * direction;
  return s;
}

double LineFitRms(const std::vector<Eigen::Vector2d>& points, const Segment2& s) {
  const Eigen::Vector2d d = s.b - s.a;
  const double length = d.norm();
  if (points.empty() || length <= 0.0) return 0.0;
  const Eigen::Vector2d normal(-d.y() / length, d.x() / length);
  double sum = 0.0;
  for (const Eigen::Vector2d& p : points) {
    const double r = (p - s.a).dot(normal);
    sum += r * r;
  }
  return std::sqrt(sum / static_cast<double>(points.size()));
}

bool CollinearMergeOptions::Check(std::string* why) const {
  if (!(max_angle_deg >= 0.0 && max_angle_deg < 90.0)) {
    *why = "merge max_angle_deg must be in [0, 90)";
    return false;
  }
  if (!(max_offset_px >= 0.0 && std::isfinite(max_offset_px))) {
    *why = "merge max_offset_px must be finite and >= 0";
    return false;
  }
  if (!(max_gap_px >= 0.0 && std::isfinite(max_gap_px))) {
    *why = "merge max_gap_px must be finite and >= 0";
    return false;
  }
  return true;
}

double LineAngle(const Segment2& a, const Segment2& b) {
  const Eigen::Vector2d da = a.b - a.a, db = b.b - b.a;
  const double cross = std::abs(Cross2(da, db)), dot = std::abs(da.dot(db));
  return std::atan2(cross, dot);
}

namespace {

// Perpendicular distance of p from the infinite line through s (s of positive length).
double DistanceToLine(const Eigen::Vector2d& p, const Segment2& s) {
  const Eigen::Vector2d d = s.b - s.a;
  return std::abs(Cross2(d, p - s.a)) / d.norm();
}

}  // namespace

bool AreCollinearFragments(const Segment2& a, const Segment2& b,
                           const CollinearMergeOptions& options) {
  const double length_a = a.Length(), length_b = b.Length();
  if (length_a <= 0.0 || length_b <= 0.0) return false;
  if (LineAngle(a, b) > DegToRad(options.max_angle_deg)) return false;
  const Segment2& longer = length_a >= length_b ? a : b;
  const Segment2& shorter = length_a >= length_b ? b : a;
  if (DistanceToLine(shorter.a, longer) > options.max_offset_px ||
      DistanceToLine(shorter.b, longer) > options.max_offset_px) {
    return false;
  }
  // Intervals along a's direction; the gap is the distance between them (negative: overlap).
  const Eigen::Vector2d direction = (a.b - a.a) / length_a;
  const double tb1 = (b.a - a.a).dot(direction), tb2 = (b.b - a.a).dot(direction);
  const double gap = std::max(std::min(tb1, tb2) - length_a, -std::max(tb1, tb2));
  return gap <= options.max_gap_px;
}

Segment2 MergeSegmentPair(const Segment2& a, const Segment2& b) {
  const double length_a = a.Length(), length_b = b.Length();
  const Segment2& longer = length_a >= length_b ? a : b;
  const Eigen::Vector2d reference = longer.b - longer.a;
  Eigen::Vector2d da = a.b - a.a, db = b.b - b.a;
  if (da.dot(reference) < 0.0) da = -da;
  if (db.dot(reference) < 0.0) db = -db;
  // Unit directions weighted by length: the sum of the (aligned) difference vectors.
  Eigen::Vector2d direction = da + db;
  const double total = length_a + length_b;
  if (direction.norm() <= 0.0 || total <= 0.0) return longer;
  direction.normalize();
  const Eigen::Vector2d centre = (length_a * a.Mid() + length_b * b.Mid()) / total;
  double t_min = std::numeric_limits<double>::infinity(), t_max = -t_min;
  for (const Eigen::Vector2d* p : {&a.a, &a.b, &b.a, &b.b}) {
    const double t = (*p - centre).dot(direction);
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
  }
  return {centre + t_min * direction, centre + t_max * direction};
}

std::vector<Segment2> MergeCollinearSegments(std::vector<Segment2> segments,
                                             const CollinearMergeOptions& options) {
  auto longer_first = [](const Segment2& x, const Segment2& y) { return x.Length() > y.Length(); };
  std::sort(segments.begin(), segments.end(), longer_first);
  std::vector<bool> absorbed(segments.size(), false);
  bool changed = true;
  while (changed) {
    changed = false;
    for (size_t i = 0; i < segments.size(); ++i) {
      if (absorbed[i]) continue;
      for (size_t j = i + 1; j < segments.size(); ++j) {
        if (absorbed[j] || !AreCollinearFragments(segments[i], segments[j], options)) continue;
        segments[i] = MergeSegmentPair(segments[i], segments[j]);
        absorbed[j] = true;
        changed = true;
        j = i;  // the grown segment may now reach fragments it skipped
      }
    }
  }
  std::vector<Segment2> merged;
  for (size_t i = 0; i < segments.size(); ++i) {
    if (!absorbed[i]) merged.push_back(segments[i]);
  }
  std::sort(merged.begin(), merged.end(), longer_first);
  return merged;
}

}  // namespace linetrack
