// Construction of the view-invariant regions (docs/models.md): a convex decomposition of the
// navigable area by the lines of its boundary, of the occluders and of a grid, refined by the
// event rays; then a conservative visibility list per region.
#include "models/view_invariant_regions.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "models/convex_polygon.h"
#include "models/errors.h"
#include "models/plan_arrangement.h"
#include "models/plan_visibility.h"

namespace linetrack {
namespace {

// Cells thinner than this are not cut off (m^2); points closer than this are one (metres).
constexpr double kMinCellArea = 1e-8;
constexpr double kPlanTolerance = 1e-6;

struct Cell {
  Ring2 ring;
  Eigen::Vector2d lo, hi;  // bounding box
};

Cell MakeCell(Ring2 ring) {
  Cell cell{std::move(ring), {}, {}};
  cell.lo = cell.hi = cell.ring.front();
  for (const Eigen::Vector2d& p : cell.ring) {
    cell.lo = cell.lo.cwiseMin(p);
    cell.hi = cell.hi.cwiseMax(p);
  }
  return cell;
}

// One sign per undirected line, so that duplicates sort next to each other.
Line2 Canonical(Line2 line) {
  if (line.normal.x() < -1e-12 || (std::abs(line.normal.x()) <= 1e-12 && line.normal.y() < 0.0)) {
    line.normal = -line.normal;
    line.offset = -line.offset;
  }
  return line;
}

// Splits every cell that `line` cuts (only cells whose box meets [lo, hi] when given).
void SplitCells(const Line2& line, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                const Segment2* segment, std::vector<Cell>* cells) {
  const size_t count = cells->size();
  for (size_t i = 0; i < count; ++i) {
    Cell& cell = (*cells)[i];
    if ((cell.hi.array() < lo.array()).any() || (cell.lo.array() > hi.array()).any()) continue;
    if (segment != nullptr) {
      double t0 = 0.0, t1 = 0.0;
      if (!ClipSegmentToConvex(cell.ring, *segment, &t0, &t1) ||
          (t1 - t0) * segment->Length() < kPlanTolerance) {
        continue;
      }
    }
    Ring2 positive, negative;
    if (!SplitConvex(cell.ring, line, kMinCellArea, &positive, &negative)) continue;
    cell = MakeCell(std::move(positive));
    cells->push_back(MakeCell(std::move(negative)));
  }
}

// The navigable area's bounding box cut by the lines of its boundary, of the occluders and of the
// grid; the cells inside the area (outer boundary minus holes) are kept.
std::vector<Cell> InitialCells(const NavigableArea& area, const std::vector<Segment2>& occluders,
                               double grid_pitch) {
  const Eigen::Vector2d lo = area.BoundsMin(), hi = area.BoundsMax();
  std::vector<Line2> lines;
  auto add_ring = [&](const Polygon2& polygon) {
    for (size_t i = 0; i < polygon.vertices.size(); ++i) {
      const Eigen::Vector2d& a = polygon.vertices[i];
      const Eigen::Vector2d& b = polygon.vertices[(i + 1) % polygon.vertices.size()];
      if ((b - a).norm() > kPlanTolerance) lines.push_back(Canonical(Line2::Through(a, b)));
    }
  };
  add_ring(area.outer());
  for (const Polygon2& hole : area.holes())
    add_ring(hole);
  for (const Segment2& s : occluders)
    lines.push_back(Canonical(Line2::Through(s.a, s.b)));
  if (grid_pitch > 0.0) {
    for (double x = lo.x() + grid_pitch; x < hi.x() - 1e-3 * grid_pitch; x += grid_pitch) {
      lines.push_back({Eigen::Vector2d::UnitX(), x});
    }
    for (double y = lo.y() + grid_pitch; y < hi.y() - 1e-3 * grid_pitch; y += grid_pitch) {
      lines.push_back({Eigen::Vector2d::UnitY(), y});
    }
  }
  std::sort(lines.begin(), lines.end(), [](const Line2& a, const Line2& b) {
    const double angle_a = std::atan2(a.normal.y(), a.normal.x());
    const double angle_b = std::atan2(b.normal.y(), b.normal.x());
    return angle_a != angle_b ? angle_a < angle_b : a.offset < b.offset;
  });
  std::vector<Cell> cells = {MakeCell({lo, {hi.x(), lo.y()}, hi, {lo.x(), hi.y()}})};
  const Line2* previous = nullptr;
  for (const Line2& line : lines) {
    if (previous != nullptr && (line.normal - previous->normal).norm() < 1e-9 &&
        std::abs(line.offset - previous->offset) < kPlanTolerance) {
      continue;
    }
    SplitCells(line, lo, hi, nullptr, &cells);
    previous = &line;
  }
  std::vector<Cell> inside;
  for (Cell& cell : cells) {
    const Eigen::Vector2d c = RingCentroid(cell.ring);
    if (!area.outer().Contains(c)) continue;
    const bool in_hole = std::any_of(area.holes().begin(), area.holes().end(),
                                     [&](const Polygon2& hole) { return hole.Contains(c); });
    if (!in_hole) inside.push_back(std::move(cell));
  }
  return inside;
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

// Event rays (Simsarian et al. 1996): from an occluding vertex c, away from a model vertex v that
// c can start to hide (v sees c, and the walls at c lie on one side of the line v-c), up to the
// next occluder or the area's box. Crossing one makes v appear or disappear behind c.
std::vector<Segment2> EventRays(const WireframeModel& model, const std::vector<Segment2>& occluders,
                                const NavigableArea& area) {
  std::vector<PlanWall> walls;
  for (const Segment2& s : occluders)
    walls.push_back({s, Eigen::Vector2d::Zero()});
  const PlanArrangement arrangement = PlanArrangement::Build(walls, kPlanTolerance);
  std::vector<Eigen::Vector2d> points;
  for (const Eigen::Vector3d& v : model.vertices()) {
    const Eigen::Vector2d p = v.head<2>();
    const bool known = std::any_of(points.begin(), points.end(), [&](const Eigen::Vector2d& q) {
      return (q - p).norm() <= kPlanTolerance;
    });
    if (!known) points.push_back(p);
  }
  const Eigen::Vector2d lo = area.BoundsMin(), hi = area.BoundsMax();
  std::vector<Segment2> rays;
  for (size_t c_id = 0; c_id < arrangement.vertices().size(); ++c_id) {
    const Eigen::Vector2d& c = arrangement.vertices()[c_id];
    const std::vector<int>& around = arrangement.Neighbours(static_cast<int>(c_id));
    if (around.empty() || (c.array() < lo.array()).any() || (c.array() > hi.array()).any()) {
      continue;
    }
    std::vector<double> angles;
    for (const Eigen::Vector2d& v : points) {
      if ((c - v).norm() <= kPlanTolerance) continue;
      const Eigen::Vector2d d = (c - v).normalized();
      double side_lo = 0.0, side_hi = 0.0;
      for (int w : around) {
        const Eigen::Vector2d e = (arrangement.vertices()[w] - c).normalized();
        side_lo = std::min(side_lo, Cross2(d, e));
        side_hi = std::max(side_hi, Cross2(d, e));
      }
      if (side_lo < -1e-9 && side_hi > 1e-9) continue;  // c is not on the silhouette seen from v
      const bool sees = std::none_of(occluders.begin(), occluders.end(),
                                     [&](const Segment2& o) { return CrossesBetween(v, c, o); });
      if (sees) angles.push_back(std::atan2(d.y(), d.x()));
    }
    std::sort(angles.begin(), angles.end());
    for (size_t k = 0; k < angles.size(); ++k) {
      if (k > 0 && angles[k] - angles[k - 1] < 1e-9) continue;
      const Eigen::Vector2d d(std::cos(angles[k]), std::sin(angles[k]));
      // Exit from the box, then the first occluder crossed.
      double t_end = std::numeric_limits<double>::infinity();
      for (int axis = 0; axis < 2; ++axis) {
        if (d[axis] > 1e-15) t_end = std::min(t_end, (hi[axis] - c[axis]) / d[axis]);
        if (d[axis] < -1e-15) t_end = std::min(t_end, (lo[axis] - c[axis]) / d[axis]);
      }
      for (const Segment2& o : occluders) {
        const Eigen::Vector2d e = o.b - o.a;
        const double denom = Cross2(d, e);
        if (std::abs(denom) <= 1e-12 * e.norm()) continue;
        const double t = Cross2(o.a - c, e) / denom, u = Cross2(o.a - c, d) / denom;
        if (t > kPlanTolerance && u >= 0.0 && u <= 1.0) t_end = std::min(t_end, t);
      }
      if (t_end > kPlanTolerance) rays.push_back({c, c + t_end * d});
    }
  }
  return rays;
}

// Convex pieces of the closed loops of occluders that contain no navigable cell.
std::vector<Ring2> Solids(const std::vector<Segment2>& occluders, const std::vector<Cell>& cells) {
  std::vector<PlanWall> walls;
  for (const Segment2& s : occluders)
    walls.push_back({s, Eigen::Vector2d::Zero()});
  const PlanArrangement arrangement = PlanArrangement::Build(walls, kPlanTolerance);
  std::vector<Ring2> solids;
  for (const PlanCycle& cycle : arrangement.cycles()) {
    if (cycle.signed_area <= kMinCellArea) continue;
    const Ring2 ring = arrangement.CycleRing(cycle);
    if (ring.size() < 3) continue;
    const bool navigable = std::any_of(cells.begin(), cells.end(), [&](const Cell& cell) {
      return RingContains(ring, RingCentroid(cell.ring));
    });
    if (navigable) continue;
    for (Ring2& piece : ConvexPieces(ring))
      solids.push_back(std::move(piece));
  }
  return solids;
}

// The floor-plan footprint of an edge: one point for a vertical edge, else its two end points.
Ring2 Footprint(const ModelEdge& edge) {
  const Eigen::Vector2d a = edge.segment.a.head<2>(), b = edge.segment.b.head<2>();
  if ((b - a).norm() <= 1e-9) return {0.5 * (a + b)};
  return {a, b};
}

std::vector<RegionEdge> VisibilityList(const Ring2& region, const WireframeModel& model,
                                       const std::vector<Segment2>& occluders,
                                       const std::vector<Ring2>& solids, double margin) {
  std::vector<RegionEdge> visible;
  for (const ModelEdge& edge : model.edges()) {
    const Ring2 footprint = Footprint(edge);
    const bool hidden = std::any_of(occluders.begin(), occluders.end(),
                                    [&](const Segment2& o) {
                                      return HiddenByWall(region, footprint, o, margin);
                                    }) ||
                        std::any_of(solids.begin(), solids.end(), [&](const Ring2& solid) {
                          return HiddenBySolid(region, footprint, solid, margin);
                        });
    if (hidden) continue;
    const BearingRange range = BearingsToFootprint(region, footprint);
    visible.push_back({edge.id, range.min, range.max, range.all});
  }
  return visible;
}

}  // namespace

bool ViewInvariantRegionsOptions::Check(std::string* why) const {
  if (!(full_height_tolerance >= 0.0 && full_height_tolerance < 1.0)) {
    *why = "full_height_tolerance must be in [0, 1) metres";
    return false;
  }
  if (!std::isfinite(camera_top)) {
    *why = "camera_top must be finite (metres)";
    return false;
  }
  if (!(grid_pitch == 0.0 || (grid_pitch >= 0.05 && grid_pitch <= 1e3))) {
    *why = "grid_pitch must be 0 (no grid) or in [0.05, 1000] metres";
    return false;
  }
  if (!(hidden_margin >= 1e-6 && hidden_margin < 0.1)) {
    *why = "hidden_margin must be in [1e-6, 0.1) metres";
    return false;
  }
  return true;
}

ViewInvariantRegions ViewInvariantRegions::Build(const WireframeModel& model,
                                                 const NavigableArea& area,
                                                 const ViewInvariantRegionsOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError(Located(model.path(), 0, why));
  ViewInvariantRegions vir;
  vir.num_edges_ = static_cast<int>(model.edges().size());
  for (const ModelEdge& edge : model.edges()) {
    const Ring2 footprint = Footprint(edge);
    vir.footprints_.push_back({footprint.front(), footprint.back()});
  }
  if (area.outer().vertices.size() < 3) return vir;
  vir.occluders_ = FullHeightOccluders(model, options.full_height_tolerance, options.camera_top);
  std::vector<Cell> cells = InitialCells(area, vir.occluders_, options.grid_pitch);
  if (options.event_rays) {
    for (const Segment2& ray : EventRays(model, vir.occluders_, area)) {
      SplitCells(Line2::Through(ray.a, ray.b), ray.a.cwiseMin(ray.b), ray.a.cwiseMax(ray.b), &ray,
                 &cells);
    }
  }
  const std::vector<Ring2> solids = Solids(vir.occluders_, cells);
  for (const Ring2& solid : solids)
    vir.solids_.push_back(Polygon2{solid});
  for (const Cell& cell : cells) {
    ViewRegion region;
    region.polygon.vertices = cell.ring;
    region.visible =
        VisibilityList(cell.ring, model, vir.occluders_, solids, options.hidden_margin);
    vir.regions_.push_back(std::move(region));
  }
  vir.BuildGrid(area);
  return vir;
}

}  // namespace linetrack
