#include "models/segment_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace linetrack {
namespace {

// Parameters [t0, t1] of a -> b (t in [0, 1]) inside the box [lo, hi]; false when it misses.
bool ClipToBox(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& lo,
               const Eigen::Vector2d& hi, double* t0, double* t1) {
  *t0 = 0.0;
  *t1 = 1.0;
  const Eigen::Vector2d d = b - a;
  for (int axis = 0; axis < 2; ++axis) {
    if (std::abs(d[axis]) < 1e-300) {
      if (a[axis] < lo[axis] || a[axis] > hi[axis]) return false;
      continue;
    }
    double ta = (lo[axis] - a[axis]) / d[axis], tb = (hi[axis] - a[axis]) / d[axis];
    if (ta > tb) std::swap(ta, tb);
    *t0 = std::max(*t0, ta);
    *t1 = std::min(*t1, tb);
    if (*t0 > *t1) return false;
  }
  return true;
}

// Parameter t along a + t d where it meets segment s (touching counts); infinity when it does not.
double RayHit(const Eigen::Vector2d& a, const Eigen::Vector2d& d, const Segment2& s) {
  const Eigen::Vector2d e = s.b - s.a;
  const double denom = Cross2(d, e);
  if (std::abs(denom) <= 1e-12 * d.norm() * e.norm())
    return std::numeric_limits<double>::infinity();
  const double t = Cross2(s.a - a, e) / denom, u = Cross2(s.a - a, d) / denom;
  return u >= 0.0 && u <= 1.0 ? t : std::numeric_limits<double>::infinity();
}

}  // namespace

SegmentGrid::SegmentGrid(std::vector<Segment2> segments, double min_cell)
    : segments_(std::move(segments)), stamp_(segments_.size(), 0) {
  if (segments_.empty()) {
    cells_.assign(1, {});
    return;
  }
  Eigen::Vector2d lo = segments_.front().a, hi = lo;
  for (const Segment2& s : segments_) {
    lo = lo.cwiseMin(s.a).cwiseMin(s.b);
    hi = hi.cwiseMax(s.a).cwiseMax(s.b);
  }
  const Eigen::Vector2d extent = (hi - lo).cwiseMax(Eigen::Vector2d::Constant(min_cell));
  cell_ = std::max(min_cell, std::sqrt(extent.prod() / segments_.size()));
  // Grid lines off round coordinates, so that axis-aligned walls do not lie on them.
  origin_ = lo - cell_ * Eigen::Vector2d(0.3183098861837907, 0.2718281828459045);
  cols_ = static_cast<int>((hi.x() - origin_.x()) / cell_) + 1;
  rows_ = static_cast<int>((hi.y() - origin_.y()) / cell_) + 1;
  cells_.assign(static_cast<size_t>(cols_) * rows_, {});
  for (size_t i = 0; i < segments_.size(); ++i) {
    Walk(segments_[i].a, segments_[i].b, [&](size_t cell) {
      cells_[cell].push_back(static_cast<int>(i));
      return false;
    });
  }
}

bool SegmentGrid::ClipToGrid(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double* t0,
                             double* t1) const {
  return ClipToBox(a, b, origin_, origin_ + cell_ * Eigen::Vector2d(cols_, rows_), t0, t1);
}

void SegmentGrid::BandExtent(const Eigen::Vector2d& p, const Eigen::Vector2d& q, double y0,
                             double y1, double* x_lo, double* x_hi) {
  const Eigen::Vector2d& low = p.y() <= q.y() ? p : q;
  const Eigen::Vector2d& high = p.y() <= q.y() ? q : p;
  if (high.y() < y0 || low.y() > y1) return;
  const double dy = high.y() - low.y();
  // The ends of the part inside the band (a horizontal edge lies in it whole).
  double t0 = 0.0, t1 = 1.0;
  if (dy > 0.0) {
    t0 = std::max(0.0, (y0 - low.y()) / dy);
    t1 = std::min(1.0, (y1 - low.y()) / dy);
  }
  for (double t : {t0, t1}) {
    const double x = low.x() + t * (high.x() - low.x());
    *x_lo = std::min(*x_lo, x);
    *x_hi = std::max(*x_hi, x);
  }
}

std::vector<int> SegmentGrid::Near(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const {
  ++query_;
  std::vector<int> out;
  for (int r = Row(lo.y()); r <= Row(hi.y()); ++r) {
    for (int c = Col(lo.x()); c <= Col(hi.x()); ++c) {
      for (int i : cells_[static_cast<size_t>(r) * cols_ + c]) {
        if (stamp_[i] == query_) continue;
        stamp_[i] = query_;
        out.push_back(i);
      }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

double SegmentGrid::FirstHit(const Eigen::Vector2d& a, const Eigen::Vector2d& d, double min_t,
                             double max_t) const {
  double best = max_t;
  Along(a + min_t * d, a + max_t * d, [&](int i) {
    const double t = RayHit(a, d, segments_[i]);
    if (t >= min_t && t < best) best = t;
    return false;
  });
  return best;
}

}  // namespace linetrack
