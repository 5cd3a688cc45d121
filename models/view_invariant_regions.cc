// Construction of the view-invariant regions (docs/models.md), storey by storey: the cells of the
// navigable area (models/vir_cells.h), then a conservative visibility list per region.
#include "models/view_invariant_regions.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <thread>

#include "models/convex_polygon.h"
#include "models/errors.h"
#include "models/plan_arrangement.h"
#include "models/plan_visibility.h"
#include "models/segment_grid.h"
#include "models/vir_cells.h"
#include "models/vir_lists.h"

namespace linetrack {
namespace {

// Points closer than this are one (metres).
constexpr double kPlanTolerance = 1e-6;
// Event rays are cast from occluding vertices for points within this range (metres); a closed
// loop of occluders with at most this many sides is a solid.
constexpr double kEventRange = 15.0;
constexpr int kMaxSolidSides = 16;
// A cell split into at least this many regions keeps its edges' occluders: gathering them costs
// about as much as a few walks along each sight line.
constexpr int kRegionsToKeepOccluders = 8;

// The floor-plan footprint of an edge: one point for a vertical edge, else its two end points.
Ring2 Footprint(const ModelEdge& edge) {
  const Eigen::Vector2d a = edge.segment.a.head<2>(), b = edge.segment.b.head<2>();
  if ((b - a).norm() <= 1e-9) return {0.5 * (a + b)};
  return {a, b};
}

// Per model edge, the faces it bounds when all of them are one-sided (no camera sees their back):
// the edge is out of sight from behind all of them. Empty for 3D lines and edges of a face that
// can be seen from both sides.
std::vector<std::vector<int>> OneSidedFacesOfEdges(const WireframeModel& model) {
  std::map<std::pair<int, int>, int> edge_of;
  for (const ModelEdge& edge : model.edges())
    edge_of[std::minmax(edge.v0, edge.v1)] = edge.id;
  std::vector<std::vector<int>> faces(model.edges().size());
  std::vector<char> seen_behind(model.edges().size(), 0);
  for (size_t f = 0; f < model.faces().size(); ++f) {
    const std::vector<int>& v = model.faces()[f].vertices;
    for (size_t i = 0; i < v.size(); ++i) {
      const auto it = edge_of.find(std::minmax(v[i], v[(i + 1) % v.size()]));
      if (it == edge_of.end()) continue;
      faces[it->second].push_back(static_cast<int>(f));
      if (!model.faces()[f].one_sided) seen_behind[it->second] = 1;
    }
  }
  for (const ModelEdge& edge : model.edges()) {
    if (edge.from_line || seen_behind[edge.id]) faces[edge.id].clear();
  }
  return faces;
}

// Distinct floor-plan points of the ends of the edges `ids`.
std::vector<Eigen::Vector2d> PlanPoints(const WireframeModel& model, const std::vector<int>& ids) {
  std::vector<Eigen::Vector2d> points;
  for (int id : ids) {
    for (const Eigen::Vector3d& end : {model.edges()[id].segment.a, model.edges()[id].segment.b})
      points.push_back(end.head<2>());
  }
  std::sort(points.begin(), points.end(), LexicographicLess);
  std::vector<Eigen::Vector2d> distinct;
  for (const Eigen::Vector2d& p : points) {
    const bool known = std::any_of(distinct.rbegin(), distinct.rend(),
                                   [&](const auto& q) { return (q - p).norm() <= kPlanTolerance; });
    if (!known) distinct.push_back(p);
  }
  return distinct;
}

// True when horizontal faces with z in [z_lo, z_hi] (a slab between two storeys, door heads) lie
// over the centroid of every cell.
bool SlabCovers(const WireframeModel& model, const std::vector<Cell>& cells, double z_lo,
                double z_hi) {
  std::vector<Ring2> slab;
  for (const ModelFace& face : model.faces()) {
    if (!face.horizontal || face.Degenerate()) continue;
    const double z = face.corners.front().z();
    if (z < z_lo || z > z_hi) continue;
    Ring2 ring;
    for (const Eigen::Vector3d& c : face.corners)
      ring.push_back(c.head<2>());
    slab.push_back(std::move(ring));
  }
  return !cells.empty() && std::all_of(cells.begin(), cells.end(), [&](const Cell& cell) {
    const Eigen::Vector2d c = RingCentroid(cell.ring);
    return std::any_of(slab.begin(), slab.end(),
                       [&](const Ring2& ring) { return RingContains(ring, c); });
  });
}

// The edges storey s lists. A slab that covers the storey above (below) hides everything above
// its walls' top (below its floor): those edges are dropped, and the others are seen only through
// their part within the band, where the storey's occluders hide them. Without a slab, edges
// beyond the band [z_lo, z_hi] (metres) may be seen over the walls: never hidden.
StoreyEdges EdgesOfStorey(const WireframeModel& model, const std::vector<Storey>& storeys, int s,
                          const std::vector<Cell>& cells, double z_lo, double z_hi) {
  constexpr double kTol = 0.05;
  const int n = static_cast<int>(storeys.size());
  // Above a region: a ceiling, or a door head, anywhere above the cameras' feet.
  const bool closed_below =
      s > 0 && SlabCovers(model, cells, storeys[s - 1].top_z - kTol, storeys[s].floor_z + kTol);
  const bool closed_above = s + 1 < n && SlabCovers(model, cells, storeys[s].floor_z + kTol,
                                                    storeys[s + 1].floor_z + kTol);
  StoreyEdges edges;
  for (const ModelEdge& edge : model.edges()) {
    const double e_lo = std::min(edge.segment.a.z(), edge.segment.b.z());
    const double e_hi = std::max(edge.segment.a.z(), edge.segment.b.z());
    if ((closed_above && e_lo > storeys[s].top_z + kTol) ||
        (closed_below && e_hi < storeys[s].floor_z - kTol)) {
      continue;
    }
    edges.ids.push_back(edge.id);
    edges.footprints.push_back(Footprint(edge));
    const bool in_band =
        (closed_below || e_lo >= z_lo - kTol) && (closed_above || e_hi <= z_hi + kTol);
    edges.in_band.push_back(in_band ? 1 : 0);
  }
  std::map<std::pair<char, std::vector<double>>, int> first;
  for (size_t k = 0; k < edges.ids.size(); ++k) {
    Ring2 points = edges.footprints[k];
    std::sort(points.begin(), points.end(), LexicographicLess);
    std::vector<double> key;
    for (const Eigen::Vector2d& p : points)
      key.insert(key.end(), {p.x(), p.y()});
    edges.same_as.push_back(
        first.emplace(std::make_pair(edges.in_band[k], std::move(key)), static_cast<int>(k))
            .first->second);
  }
  return edges;
}

// Calls job(i, occluders) for i in [0, n) on `threads` threads (0: the hardware's; at most one per
// 64 jobs): thread w takes i = w, w + workers, ..., each with its own copy of the occluders (their
// walks keep per-query marks). The jobs must be independent.
template <typename Job>
void ForEach(size_t n, int threads, const StoreyOccluders& occluders, const Job& job) {
  const size_t wanted =
      threads > 0 ? static_cast<size_t>(threads) : std::thread::hardware_concurrency();
  const size_t workers = std::max<size_t>(1, std::min(wanted, n / 64));
  // A job's exception is caught in its thread and rethrown here once every thread has ended.
  std::vector<std::exception_ptr> failures(workers);
  auto run = [&](size_t w, const StoreyOccluders& own) {
    try {
      for (size_t i = w; i < n; i += workers)
        job(i, own);
    } catch (...) {
      failures[w] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (size_t w = 1; w < workers; ++w)
    pool.emplace_back([&, w] { run(w, StoreyOccluders(occluders)); });
  run(0, occluders);
  for (std::thread& thread : pool)
    thread.join();
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
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
  if (!(event_ray_separation_deg >= 0.0 && event_ray_separation_deg <= 90.0)) {
    *why = "event_ray_separation_deg must be in [0, 90] degrees";
    return false;
  }
  if (!(min_region_size >= 0.0 && min_region_size <= 100.0)) {
    *why = "min_region_size must be in [0, 100] metres";
    return false;
  }
  if (!(threads >= 0 && threads <= 256)) {
    *why = "threads must be in [0, 256] (0: the hardware's)";
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
  vir.storeys_ = area.storeys();
  vir.hidden_margin_ = options.hidden_margin;
  vir.storey_walls_.resize(area.storeys().size());
  for (int s = 0; s < static_cast<int>(area.storeys().size()); ++s)
    vir.BuildStorey(model, area, s, options);
  vir.BuildGrid(area);
  return vir;
}

void ViewInvariantRegions::BuildStorey(const WireframeModel& model, const NavigableArea& area,
                                       int s, const ViewInvariantRegionsOptions& options) {
  std::vector<const AreaPart*> parts;
  for (const AreaPart& part : area.parts()) {
    if (part.storey == s && part.outer.vertices.size() >= 3) parts.push_back(&part);
  }
  if (parts.empty()) return;
  const std::vector<Storey>& storeys = area.storeys();
  const double tol = options.full_height_tolerance;
  const double z_lo = storeys[s].floor_z, z_hi = std::max(storeys[s].top_z, options.camera_top);
  const std::vector<Segment2> walls = OccludersInBand(model, z_lo + tol, z_hi - tol);
  std::vector<Segment2> stoppers = walls;
  Eigen::Vector2d lo = parts.front()->outer.vertices.front(), hi = lo;
  for (const AreaPart* part : parts) {
    for (const Polygon2* ring : {&part->outer}) {
      for (size_t i = 0; i < ring->vertices.size(); ++i) {
        stoppers.push_back({ring->vertices[i], ring->vertices[(i + 1) % ring->vertices.size()]});
        lo = lo.cwiseMin(ring->vertices[i]), hi = hi.cwiseMax(ring->vertices[i]);
      }
    }
    for (const Polygon2& hole : part->holes) {
      for (size_t i = 0; i < hole.vertices.size(); ++i)
        stoppers.push_back({hole.vertices[i], hole.vertices[(i + 1) % hole.vertices.size()]});
    }
  }
  std::vector<Cell> cells =
      InitialCells(parts, SegmentGrid(std::move(stoppers)), options.grid_pitch);
  const std::vector<Cell> initial = cells;
  StoreyEdges edges = EdgesOfStorey(model, storeys, s, cells, z_lo, z_hi);
  const std::vector<std::vector<int>> one_sided = OneSidedFacesOfEdges(model);
  edges.z_lo = z_lo;
  edges.z_hi = z_hi;
  edges.one_sided_faces = &one_sided;
  StoreyOccluders occluders{SegmentGrid(walls), {}, {}, {}, SegmentGrid({}), {}, {}, 0};
  for (const Segment2& wall : occluders.walls.segments()) {
    occluders.wall_lengths.push_back((wall.b - wall.a).norm());
    occluders.wall_lines.push_back(Line2::Through(wall.a, wall.b));
  }
  occluders.solids = Solids(walls, cells, kMaxSolidSides);
  if (options.event_rays) {
    EventRayOptions rays;
    rays.range = kEventRange;
    rays.min_separation = DegToRad(options.event_ray_separation_deg);
    for (const Segment2& ray : EventRays(PlanPoints(model, edges.ids), occluders.walls,
                                         occluders.solids, Eigen::AlignedBox2d(lo, hi), rays)) {
      SplitCells(ray, &cells, options.min_region_size);
    }
  }
  std::vector<Segment2> sides;
  for (size_t k = 0; k < occluders.solids.size(); ++k) {
    const Ring2& solid = occluders.solids[k];
    for (size_t i = 0; i < solid.size(); ++i) {
      sides.push_back({solid[i], solid[(i + 1) % solid.size()]});
      occluders.solid_of_side.push_back(static_cast<int>(k));
    }
    solids_.push_back(Polygon2{solid});
  }
  occluders.solid_sides = SegmentGrid(std::move(sides));
  occluders.seen.assign(occluders.solids.size(), 0);
  occluders_.insert(occluders_.end(), walls.begin(), walls.end());
  StoreyWalls& own = storey_walls_[s];
  own.grid = occluders.walls;
  own.lines = occluders.wall_lines;
  own.corners = WallCorners(own.grid.segments(), kPlanTolerance);
  own.hideable.assign(model.edges().size(), 0);
  for (size_t k = 0; k < edges.ids.size(); ++k)
    own.hideable[edges.ids[k]] = edges.in_band[k];
  // The initial cells' lists first; a region split from one tests only its cell's list. A cell
  // split into many regions keeps each edge's occluders for them.
  std::vector<int> regions_of(initial.size(), 0);
  for (const Cell& cell : cells)
    ++regions_of[cell.parent];
  std::vector<CellList> cell_lists(initial.size());
  ForEach(initial.size(), options.threads, occluders, [&](size_t i, const StoreyOccluders& own) {
    const CellOccluders keep =
        regions_of[i] >= kRegionsToKeepOccluders ? CellOccluders::kKeep : CellOccluders::kNone;
    cell_lists[i] = CellVisibility(initial[i].ring, model, edges, own, options.hidden_margin, keep);
  });
  const size_t first = regions_.size();
  regions_.resize(first + cells.size());
  ForEach(cells.size(), options.threads, occluders, [&](size_t i, const StoreyOccluders& own) {
    ViewRegion& region = regions_[first + i];
    region.polygon.vertices = cells[i].ring;
    region.storey = s;
    region.visible = options.direct_lists
                         ? DirectVisibility(cells[i], model, edges, own, options.hidden_margin)
                         : RegionVisibility(cells[i], model, edges, cell_lists[cells[i].parent],
                                            own, options.hidden_margin);
  });
}

}  // namespace linetrack
