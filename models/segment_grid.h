// Floor-plan segments in a uniform grid: the segments near a box, and those along a segment in
// the order a walk from its start meets their cells (for the first wall a ray hits, or the walls
// a sight line crosses). Used by the view-invariant regions and the plan arrangement.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "models/geometry.h"

namespace linetrack {

class SegmentGrid {
 public:
  // About one cell per segment, cells no smaller than `min_cell` metres.
  explicit SegmentGrid(std::vector<Segment2> segments, double min_cell = 0.25);

  const std::vector<Segment2>& segments() const { return segments_; }

  // Indices of the segments whose cells meet the box [lo, hi] (sorted, each once).
  std::vector<int> Near(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const;

  // Calls visit(i) once for each segment registered in a cell that segment a -> b passes
  // through, cell by cell from a; stops when visit returns true (and returns true then).
  template <typename Visit>
  bool Along(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Visit& visit) const {
    ++query_;
    return Walk(a, b, [&](size_t cell) {
      for (int i : cells_[cell]) {
        if (stamp_[i] == query_) continue;
        stamp_[i] = query_;
        if (visit(i)) return true;
      }
      return false;
    });
  }

  // As Along, without the marks that visit each segment once: a segment registered in several
  // cells on the way is visited once per cell. Safe to call from several threads at once.
  template <typename Visit>
  bool AlongEveryCell(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                      const Visit& visit) const {
    return Walk(a, b, [&](size_t cell) {
      return std::any_of(cells_[cell].begin(), cells_[cell].end(), visit);
    });
  }

  // Calls visit(i) once for each segment registered in a cell that the convex polygon `ring`,
  // grown by `margin` metres, meets (a superset of the segments within `margin` of it).
  template <typename Visit>
  void InConvex(const std::vector<Eigen::Vector2d>& ring, double margin, const Visit& visit) const {
    ++query_;
    Eigen::Vector2d lo = ring.front(), hi = lo;
    for (const Eigen::Vector2d& p : ring)
      lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    for (int r = Row(lo.y() - margin); r <= Row(hi.y() + margin); ++r) {
      // The polygon's x extent within this row's band: that of its edges clipped to the band.
      const double y0 = std::max(lo.y(), origin_.y() + r * cell_ - margin);
      const double y1 = std::min(hi.y(), origin_.y() + (r + 1) * cell_ + margin);
      if (y0 > y1) continue;  // a row clamped onto a polygon outside the grid
      double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo;
      for (size_t k = 0; k < ring.size(); ++k) {
        const Eigen::Vector2d &p = ring[k], &q = ring[(k + 1) % ring.size()];
        BandExtent(p, q, y0, y1, &x_lo, &x_hi);
      }
      if (!(x_lo <= x_hi)) continue;
      for (int c = Col(x_lo - margin); c <= Col(x_hi + margin); ++c) {
        for (int i : cells_[static_cast<size_t>(r) * cols_ + c]) {
          if (stamp_[i] == query_) continue;
          stamp_[i] = query_;
          visit(i);
        }
      }
    }
  }

  // The parameter t >= min_t (along a -> a + t d, d of any length) of the first segment the ray
  // crosses or touches, up to max_t; max_t when none.
  double FirstHit(const Eigen::Vector2d& a, const Eigen::Vector2d& d, double min_t,
                  double max_t) const;

 private:
  // floor(value) clamped to [0, count - 1] before the cast (NaN gives 0): no overflow.
  static int ClampedIndex(double value, int count) {
    const double f = std::floor(value);
    if (!(f > 0.0)) return 0;
    return f >= count - 1 ? count - 1 : static_cast<int>(f);
  }
  int Col(double x) const { return ClampedIndex((x - origin_.x()) / cell_, cols_); }
  int Row(double y) const { return ClampedIndex((y - origin_.y()) / cell_, rows_); }
  // Calls visit(cell) for the cells segment a -> b passes through, from a (Amanatides-Woo);
  // stops when visit returns true (and returns true then).
  template <typename Visit>
  bool Walk(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Visit& visit) const {
    double t0 = 0.0, t1 = 1.0;
    if (!ClipToGrid(a, b, &t0, &t1)) return false;
    const Eigen::Vector2d d = b - a;
    const Eigen::Vector2d start = a + t0 * d, end = a + t1 * d;
    int c = Col(start.x()), r = Row(start.y());
    const int c_end = Col(end.x()), r_end = Row(end.y());
    const int step_c = d.x() > 0 ? 1 : -1, step_r = d.y() > 0 ? 1 : -1;
    const double inf = std::numeric_limits<double>::infinity();
    const double dt_c = std::abs(d.x()) > 1e-300 ? cell_ / std::abs(d.x()) : inf;
    const double dt_r = std::abs(d.y()) > 1e-300 ? cell_ / std::abs(d.y()) : inf;
    const double next_x = origin_.x() + (c + (step_c > 0 ? 1 : 0)) * cell_;
    const double next_y = origin_.y() + (r + (step_r > 0 ? 1 : 0)) * cell_;
    double t_c = std::abs(d.x()) > 1e-300 ? (next_x - a.x()) / d.x() : inf;
    double t_r = std::abs(d.y()) > 1e-300 ? (next_y - a.y()) / d.y() : inf;
    for (int guard = 0; guard < cols_ + rows_ + 2; ++guard) {
      if (visit(static_cast<size_t>(r) * cols_ + c)) return true;
      if (c == c_end && r == r_end) break;
      if (t_c < t_r) {
        if (t_c > t1) break;
        c += step_c;
        t_c += dt_c;
      } else {
        if (t_r > t1) break;
        r += step_r;
        t_r += dt_r;
      }
      if (c < 0 || r < 0 || c >= cols_ || r >= rows_) break;
    }
    return false;
  }
  // Widens [x_lo, x_hi] to the x of the part of segment p-q with y in [y0, y1].
  static void BandExtent(const Eigen::Vector2d& p, const Eigen::Vector2d& q, double y0, double y1,
                         double* x_lo, double* x_hi);
  // Parameters [t0, t1] of a -> b inside the grid's box; false when it misses.
  bool ClipToGrid(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double* t0, double* t1) const;

  std::vector<Segment2> segments_;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  double cell_ = 1.0;
  int cols_ = 1, rows_ = 1;
  std::vector<std::vector<int>> cells_;
  mutable std::vector<unsigned> stamp_;  // per segment: the query that last visited it
  mutable unsigned query_ = 0;
};

}  // namespace linetrack
