// The cells of the view-invariant regions: a convex decomposition of the navigable area by the
// walls' lines as far as they reach, refined by the event rays (docs/models.md).
#include "models/vir_cells.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "models/plan_arrangement.h"

namespace linetrack {
namespace {

// Cells thinner than this are not cut off (m^2); points closer than this are one (metres).
constexpr double kMinCellArea = 1e-8;
constexpr double kPlanTolerance = 1e-6;

// Parameter of the ray a + t d (d unit) where it leaves the box [lo, hi] (a inside).
double BoxExit(const Eigen::Vector2d& a, const Eigen::Vector2d& d, const Eigen::Vector2d& lo,
               const Eigen::Vector2d& hi) {
  double t = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 2; ++axis) {
    if (d[axis] > 1e-15) t = std::min(t, (hi[axis] - a[axis]) / d[axis]);
    if (d[axis] < -1e-15) t = std::min(t, (lo[axis] - a[axis]) / d[axis]);
  }
  return std::max(0.0, t);
}

// True when segment a-b crosses the occluder at a point away from a and b.
bool CrossesBetween(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Segment2& o) {
  const Eigen::Vector2d d = b - a, e = o.b - o.a;
  const double denom = Cross2(d, e);
  if (std::abs(denom) <= 1e-12 * d.norm() * e.norm()) return false;  // parallel: grazing
  const double t = Cross2(o.a - a, e) / denom, u = Cross2(o.a - a, d) / denom;
  const double margin = kPlanTolerance / d.norm();
  return t > margin && t < 1.0 - margin && u >= 0.0 && u <= 1.0;
}

// The segment drawn on along its line until it meets a stopper (or the box) at each end.
Segment2 Extended(const Segment2& s, const SegmentGrid& stoppers, const Eigen::Vector2d& lo,
                  const Eigen::Vector2d& hi) {
  const Eigen::Vector2d d = (s.b - s.a).normalized();
  // Walls that only touch an end do not stop it: a wall's line goes on across a door opening.
  const double forward = stoppers.FirstHit(s.b, d, kPlanTolerance, BoxExit(s.b, d, lo, hi));
  const double backward = stoppers.FirstHit(s.a, -d, kPlanTolerance, BoxExit(s.a, -d, lo, hi));
  return {s.a - backward * d, s.b + forward * d};
}

}  // namespace

Cell MakeCell(Ring2 ring, int parent) {
  Cell cell{std::move(ring), {}, {}, parent};
  cell.lo = cell.hi = cell.ring.front();
  for (const Eigen::Vector2d& p : cell.ring) {
    cell.lo = cell.lo.cwiseMin(p);
    cell.hi = cell.hi.cwiseMax(p);
  }
  return cell;
}

void SplitCells(const Segment2& segment, std::vector<Cell>* cells, double min_cell_size) {
  if (segment.Length() < kPlanTolerance) return;
  const Line2 line = Line2::Through(segment.a, segment.b);
  const Eigen::Vector2d lo = segment.a.cwiseMin(segment.b), hi = segment.a.cwiseMax(segment.b);
  const size_t count = cells->size();
  for (size_t i = 0; i < count; ++i) {
    Cell& cell = (*cells)[i];
    if ((cell.hi.array() < lo.array()).any() || (cell.lo.array() > hi.array()).any()) continue;
    if ((cell.hi - cell.lo).maxCoeff() < min_cell_size) continue;
    double t0 = 0.0, t1 = 0.0;
    if (!ClipSegmentToConvex(cell.ring, segment, &t0, &t1) ||
        (t1 - t0) * segment.Length() < kPlanTolerance) {
      continue;
    }
    Ring2 positive, negative;
    if (!SplitConvex(cell.ring, line, kMinCellArea, &positive, &negative)) continue;
    const int parent = cell.parent;
    cell = MakeCell(std::move(positive), parent);
    cells->push_back(MakeCell(std::move(negative), parent));
  }
}

std::vector<Cell> InitialCells(const std::vector<const AreaPart*>& parts,
                               const SegmentGrid& stoppers, double grid_pitch) {
  Eigen::Vector2d lo = parts.front()->outer.vertices.front(), hi = lo;
  for (const AreaPart* part : parts) {
    for (const Eigen::Vector2d& v : part->outer.vertices)
      lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  }
  std::vector<Segment2> cuts;
  for (const Segment2& s : stoppers.segments()) {
    if (s.Length() > kPlanTolerance) cuts.push_back(Extended(s, stoppers, lo, hi));
  }
  // Long walls first: the short ones then only cut the cells near them.
  std::sort(cuts.begin(), cuts.end(),
            [](const Segment2& a, const Segment2& b) { return a.Length() > b.Length(); });
  if (grid_pitch > 0.0) {
    for (double x = lo.x() + grid_pitch; x < hi.x() - 1e-3 * grid_pitch; x += grid_pitch)
      cuts.push_back({{x, lo.y()}, {x, hi.y()}});
    for (double y = lo.y() + grid_pitch; y < hi.y() - 1e-3 * grid_pitch; y += grid_pitch)
      cuts.push_back({{lo.x(), y}, {hi.x(), y}});
  }
  std::vector<Cell> cells = {MakeCell({lo, {hi.x(), lo.y()}, hi, {lo.x(), hi.y()}}, -1)};
  for (const Segment2& cut : cuts)
    SplitCells(cut, &cells);
  std::vector<Cell> inside;
  for (Cell& cell : cells) {
    const Eigen::Vector2d c = RingCentroid(cell.ring);
    const bool in_part = std::any_of(parts.begin(), parts.end(), [&](const AreaPart* part) {
      return part->outer.Contains(c) &&
             std::none_of(part->holes.begin(), part->holes.end(),
                          [&](const Polygon2& hole) { return hole.Contains(c); });
    });
    if (!in_part) continue;
    cell.parent = static_cast<int>(inside.size());
    inside.push_back(std::move(cell));
  }
  return inside;
}

std::vector<Segment2> EventRays(const std::vector<Eigen::Vector2d>& points,
                                const SegmentGrid& occluders, const std::vector<Ring2>& solids,
                                const Eigen::AlignedBox2d& box, const EventRayOptions& options) {
  const Eigen::Vector2d lo = box.min(), hi = box.max();
  const double range = options.range;
  std::vector<Eigen::Vector2d> corners;
  for (const Ring2& solid : solids)
    corners.insert(corners.end(), solid.begin(), solid.end());
  auto is_corner = [&](const Eigen::Vector2d& c) {
    return std::any_of(corners.begin(), corners.end(),
                       [&](const Eigen::Vector2d& q) { return (q - c).norm() <= kPlanTolerance; });
  };
  std::vector<PlanWall> walls;
  for (const Segment2& s : occluders.segments())
    walls.push_back({s, Eigen::Vector2d::Zero()});
  const PlanArrangement arrangement = PlanArrangement::Build(walls, kPlanTolerance);
  // The points by x, for those within range of a vertex.
  std::vector<Eigen::Vector2d> by_x = points;
  std::sort(by_x.begin(), by_x.end(),
            [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() < b.x(); });
  std::vector<Segment2> rays;
  for (size_t c_id = 0; c_id < arrangement.vertices().size(); ++c_id) {
    const Eigen::Vector2d& c = arrangement.vertices()[c_id];
    const std::vector<int>& around = arrangement.Neighbours(static_cast<int>(c_id));
    // Rays start at the corners of solids and at the free ends of walls (a partition, a jamb).
    if (around.empty() || (c.array() < lo.array()).any() || (c.array() > hi.array()).any() ||
        (around.size() > 1 && !is_corner(c))) {
      continue;
    }
    std::vector<double> angles;
    const auto first =
        std::lower_bound(by_x.begin(), by_x.end(), c.x() - range,
                         [](const Eigen::Vector2d& p, double x) { return p.x() < x; });
    for (auto it = first; it != by_x.end() && it->x() <= c.x() + range; ++it) {
      const Eigen::Vector2d& v = *it;
      const double distance = (c - v).norm();
      if (distance <= kPlanTolerance || distance > range) continue;
      const Eigen::Vector2d d = (c - v) / distance;
      double side_lo = 0.0, side_hi = 0.0;
      for (int w : around) {
        const Eigen::Vector2d e = (arrangement.vertices()[w] - c).normalized();
        side_lo = std::min(side_lo, Cross2(d, e));
        side_hi = std::max(side_hi, Cross2(d, e));
      }
      if (side_lo < -1e-9 && side_hi > 1e-9) continue;  // c is not on the silhouette seen from v
      const bool blocked = occluders.Along(
          v, c, [&](int i) { return CrossesBetween(v, c, occluders.segments()[i]); });
      if (!blocked) angles.push_back(std::atan2(d.y(), d.x()));
    }
    std::sort(angles.begin(), angles.end());
    const double separation = std::max(1e-9, options.min_separation);
    double last = -std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < angles.size(); ++k) {
      // The fan wraps at +-pi: the last ray is also kept clear of the first.
      if (angles[k] - last < separation || (k + 1 == angles.size() && k > 0 &&
                                            angles.front() + 2.0 * kPi - angles[k] < separation)) {
        continue;
      }
      last = angles[k];
      const Eigen::Vector2d d(std::cos(angles[k]), std::sin(angles[k]));
      const double t_end = occluders.FirstHit(c, d, kPlanTolerance, BoxExit(c, d, lo, hi));
      if (t_end > kPlanTolerance) rays.push_back({c, c + t_end * d});
    }
  }
  return rays;
}

std::vector<Ring2> Solids(const std::vector<Segment2>& occluders, const std::vector<Cell>& cells,
                          int max_sides) {
  std::vector<PlanWall> walls;
  for (const Segment2& s : occluders)
    walls.push_back({s, Eigen::Vector2d::Zero()});
  const PlanArrangement arrangement = PlanArrangement::Build(walls, kPlanTolerance);
  std::vector<Ring2> solids;
  for (const PlanCycle& cycle : arrangement.cycles()) {
    if (cycle.signed_area <= kMinCellArea) continue;
    const Ring2 ring = arrangement.CycleRing(cycle);
    if (ring.size() < 3 || static_cast<int>(ring.size()) > max_sides) continue;
    Eigen::Vector2d lo = ring.front(), hi = lo;
    for (const Eigen::Vector2d& p : ring)
      lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const bool navigable = std::any_of(cells.begin(), cells.end(), [&](const Cell& cell) {
      return (cell.hi.array() >= lo.array()).all() && (cell.lo.array() <= hi.array()).all() &&
             RingContains(ring, RingCentroid(cell.ring));
    });
    if (navigable) continue;
    for (Ring2& piece : ConvexPieces(ring))
      solids.push_back(std::move(piece));
  }
  return solids;
}

}  // namespace linetrack
