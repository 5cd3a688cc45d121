#include "models/free_space.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "models/plan_visibility.h"

namespace linetrack {
namespace {

// Wall bottoms closer than this are one floor level; tops closer than this one ceiling (metres).
constexpr double kLevelTolerance = 0.05;
// A storey's walls are at least this tall (metres): lower bands (a slab's edge, a parapet) are not
// storeys.
constexpr double kMinStoreyHeight = 1.8;
// A new storey's walls are at least this share of the length of the storey below's.
constexpr double kMinStoreyShare = 0.1;
// A section keeps the parts of faces covering [z - kBand, z + kBand]; corner heights closer than
// kEventTolerance are one (metres).
constexpr double kBand = 1e-4;
constexpr double kEventTolerance = 1e-6;
// Points closer than this are one (metres); cells smaller than this have no area (m^2).
constexpr double kPlanTolerance = 1e-6;
constexpr double kMinCellArea = 1e-6;
// FindWidePoint's sampling: at most about this many samples, no finer than this (metres).
constexpr double kMaxDeepSamples = 4096.0;
constexpr double kMinDeepSpacing = 0.01;
// A horizontal face tops a cell when it covers at least this share of its area.
constexpr double kTopCoverShare = 0.5;
// A box's top lies at least this far below the storey's ceiling (metres).
constexpr double kTopBelowCeiling = 0.1;

struct WallBand {
  double bottom = 0.0, top = 0.0, length = 0.0;
};

// Length-weighted mode of the tops of `walls` (clustered within kLevelTolerance): the highest top
// of the heaviest cluster.
double TypicalTop(std::vector<WallBand> walls) {
  std::sort(walls.begin(), walls.end(),
            [](const WallBand& a, const WallBand& b) { return a.top < b.top; });
  double best_weight = -1.0, best_top = walls.front().top;
  for (size_t i = 0; i < walls.size();) {
    size_t j = i;
    double weight = 0.0;
    while (j < walls.size() && walls[j].top - walls[i].top <= kLevelTolerance)
      weight += walls[j++].length;
    if (weight > best_weight) best_weight = weight, best_top = walls[j - 1].top;
    i = j;
  }
  return best_top;
}

// Plan polygon, area and height of a horizontal face.
struct HorizontalFace {
  Ring2 ring;
  double z = 0.0, area = 0.0;
};

std::vector<HorizontalFace> HorizontalFaces(const WireframeModel& model) {
  std::vector<HorizontalFace> out;
  for (const ModelFace& face : model.faces()) {
    if (!face.horizontal || face.Degenerate()) continue;
    HorizontalFace h;
    for (const Eigen::Vector3d& c : face.corners)
      h.ring.push_back(c.head<2>());
    h.z = face.corners.front().z();
    h.area = std::abs(RingSignedArea(h.ring));
    out.push_back(std::move(h));
  }
  return out;
}

}  // namespace

std::vector<Storey> DetectStoreys(const std::vector<ModelFace>& faces, double z_min, double z_max) {
  std::vector<WallBand> walls;
  for (const ModelFace& face : faces) {
    if (!face.vertical || face.Degenerate()) continue;
    WallBand w{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
               0.0};
    const Eigen::Vector2d along(-face.normal.y(), face.normal.x());
    double s_lo = std::numeric_limits<double>::infinity(), s_hi = -s_lo;
    for (const Eigen::Vector3d& c : face.corners) {
      w.bottom = std::min(w.bottom, c.z());
      w.top = std::max(w.top, c.z());
      s_lo = std::min(s_lo, along.dot(c.head<2>()));
      s_hi = std::max(s_hi, along.dot(c.head<2>()));
    }
    w.length = s_hi - s_lo;
    walls.push_back(w);
  }
  std::sort(walls.begin(), walls.end(),
            [](const WallBand& a, const WallBand& b) { return a.bottom < b.bottom; });
  std::vector<Storey> storeys;
  std::vector<double> weights;
  for (size_t i = 0; i < walls.size();) {
    size_t j = i;
    double weight = 0.0;
    while (j < walls.size() && walls[j].bottom - walls[i].bottom <= kLevelTolerance)
      weight += walls[j++].length;
    const std::vector<WallBand> group(walls.begin() + static_cast<long>(i),
                                      walls.begin() + static_cast<long>(j));
    const Storey storey{walls[i].bottom, TypicalTop(group)};
    i = j;
    if (storey.top_z - storey.floor_z < kMinStoreyHeight) continue;
    if (!storeys.empty() && (storey.floor_z < storeys.back().top_z - kLevelTolerance ||
                             weight < kMinStoreyShare * weights.back())) {
      continue;
    }
    storeys.push_back(storey);
    weights.push_back(weight);
  }
  if (storeys.empty()) storeys.push_back({z_min, z_max});
  return storeys;
}

double NavigationHeight(const Storey& storey, const FreeSpaceOptions& options) {
  return storey.floor_z +
         std::min(options.navigation_height, 0.5 * (storey.top_z - storey.floor_z));
}

int StoreyAt(const std::vector<Storey>& storeys, double z) {
  int index = 0;
  for (size_t s = 0; s < storeys.size(); ++s) {
    if (storeys[s].floor_z <= z + kLevelTolerance) index = static_cast<int>(s);
  }
  return index;
}

bool FindWidePoint(const Ring2& ring, const std::vector<Ring2>& holes, double radius,
                   Eigen::Vector2d* point) {
  if (ring.size() < 3 || !(radius > 0.0)) return false;
  std::vector<Segment2> sides;
  for (const Ring2* r : {&ring}) {
    for (size_t i = 0; i < r->size(); ++i)
      sides.push_back({(*r)[i], (*r)[(i + 1) % r->size()]});
  }
  for (const Ring2& hole : holes) {
    for (size_t i = 0; i < hole.size(); ++i)
      sides.push_back({hole[i], hole[(i + 1) % hole.size()]});
  }
  Eigen::Vector2d lo = ring.front(), hi = lo;
  for (const Eigen::Vector2d& p : ring)
    lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  // The sides in a grid of cells at least `radius` wide (at most 256 a side): a point's sides
  // within radius lie in the 3 x 3 cells around it.
  const double cell = std::max({radius, (hi.x() - lo.x()) / 256.0, (hi.y() - lo.y()) / 256.0});
  const int cols = static_cast<int>((hi.x() - lo.x()) / cell) + 1;
  const int rows = static_cast<int>((hi.y() - lo.y()) / cell) + 1;
  std::vector<std::vector<int>> grid(static_cast<size_t>(cols) * rows);
  auto at = [&](int c, int r) -> std::vector<int>* {
    if (c < 0 || r < 0 || c >= cols || r >= rows) return nullptr;
    return &grid[static_cast<size_t>(r) * cols + c];
  };
  for (size_t i = 0; i < sides.size(); ++i) {
    const Eigen::Vector2d a = sides[i].a.cwiseMin(sides[i].b) - lo;
    const Eigen::Vector2d b = sides[i].a.cwiseMax(sides[i].b) - lo;
    for (int r = static_cast<int>(a.y() / cell); r <= static_cast<int>(b.y() / cell); ++r) {
      for (int c = static_cast<int>(a.x() / cell); c <= static_cast<int>(b.x() / cell); ++c) {
        if (std::vector<int>* bucket = at(c, r)) bucket->push_back(static_cast<int>(i));
      }
    }
  }
  auto wide = [&](const Eigen::Vector2d& p) {
    const int c0 = static_cast<int>((p.x() - lo.x()) / cell);
    const int r0 = static_cast<int>((p.y() - lo.y()) / cell);
    for (int r = r0 - 1; r <= r0 + 1; ++r) {
      for (int c = c0 - 1; c <= c0 + 1; ++c) {
        const std::vector<int>* bucket = at(c, r);
        if (bucket == nullptr) continue;
        for (int i : *bucket) {
          if (DistanceToSegment(p, sides[i]) < radius) return false;
        }
      }
    }
    return true;
  };
  // Scan lines: the inside of the ring minus the holes is where an odd number of sides lie to the
  // left; samples every `step` along each line's inside intervals.
  const double step =
      std::max({kMinDeepSpacing, 0.25 * radius, std::sqrt((hi - lo).prod() / kMaxDeepSamples)});
  for (double y = lo.y() + 0.5 * step; y < hi.y(); y += step) {
    std::vector<double> crossings;
    for (const Segment2& side : sides) {
      if ((side.a.y() > y) != (side.b.y() > y)) {
        crossings.push_back(side.a.x() + (y - side.a.y()) / (side.b.y() - side.a.y()) *
                                             (side.b.x() - side.a.x()));
      }
    }
    std::sort(crossings.begin(), crossings.end());
    for (size_t k = 0; k + 1 < crossings.size(); k += 2) {
      const double x0 = crossings[k] + radius, x1 = crossings[k + 1] - radius;
      for (double x = x0; x <= x1; x += step) {
        if (wide({x, y})) {
          *point = {x, y};
          return true;
        }
      }
    }
  }
  return false;
}

PlanSection PlanSection::Build(const WireframeModel& model, double z,
                               const FreeSpaceOptions& options) {
  PlanSection section;
  section.z_ = z;
  std::vector<PlanWall> walls;
  for (const ModelFace& face : model.faces()) {
    if (!face.vertical || face.Degenerate()) continue;
    const WallInPlane wall = ToWallPlane(face);
    if (wall.z_lo > z - kBand || wall.z_hi < z + kBand) continue;
    for (const auto& [s0, s1] : FullHeightSpans(wall.s_z, z - kBand, z + kBand)) {
      const Segment2 span{wall.At(s0), wall.At(s1)};
      section.walls_.push_back(span);
      walls.push_back({span, Eigen::Vector2d::Zero()});
    }
  }
  section.arrangement_ = PlanArrangement::Build(walls, kPlanTolerance);
  const PlanArrangement& arr = section.arrangement_;
  section.component_outline_.assign(arr.num_components(), Ring2{});
  for (const PlanCycle& cycle : arr.cycles()) {
    Ring2 ring;
    for (int v : cycle.vertices)
      ring.push_back(arr.vertices()[v]);
    if (cycle.signed_area < 0.0) {
      // A component's outer boundary is its one clockwise cycle (a tree's has no area).
      std::reverse(ring.begin(), ring.end());
      section.component_outline_[cycle.component] = std::move(ring);
      continue;
    }
    if (cycle.signed_area <= kMinCellArea) continue;
    SectionCell cell;
    cell.area = cycle.signed_area;
    cell.component = cycle.component;
    cell.lo = cell.hi = ring.front();
    for (const Eigen::Vector2d& p : ring)
      cell.lo = cell.lo.cwiseMin(p), cell.hi = cell.hi.cwiseMax(p);
    cell.ring = std::move(ring);
    section.cells_.push_back(std::move(cell));
  }
  std::sort(section.cells_.begin(), section.cells_.end(),
            [](const SectionCell& a, const SectionCell& b) { return a.area < b.area; });
  // The cell around each component: the smallest cell of another component holding its outline.
  section.enclosing_of_component_.assign(arr.num_components(), -1);
  for (int c = 0; c < arr.num_components(); ++c) {
    const Ring2& outline = section.component_outline_[c];
    if (outline.empty()) continue;
    for (size_t k = 0; k < section.cells_.size(); ++k) {
      const SectionCell& cell = section.cells_[k];
      if (cell.component == c || (outline.front().array() < cell.lo.array()).any() ||
          (outline.front().array() > cell.hi.array()).any()) {
        continue;
      }
      if (RingContains(cell.ring, outline.front())) {
        section.enclosing_of_component_[c] = static_cast<int>(k);
        break;
      }
    }
  }
  section.ClassifyCells(model, options);
  return section;
}

std::vector<Ring2> PlanSection::NestedFootprints(int cell) const {
  std::vector<Ring2> out;
  for (size_t c = 0; c < enclosing_of_component_.size(); ++c) {
    if (enclosing_of_component_[c] != cell) continue;
    Ring2 ring = SimplifyRing(component_outline_[c], kPlanTolerance);
    if (ring.size() >= 3 && RingSignedArea(ring) > kMinCellArea) out.push_back(std::move(ring));
  }
  return out;
}

void PlanSection::ClassifyCells(const WireframeModel& model, const FreeSpaceOptions& options) {
  const std::vector<HorizontalFace> tops = HorizontalFaces(model);
  const std::vector<Storey>& storeys = model.storeys();
  const Storey storey = storeys.empty() ? Storey{model.BoxMin().z(), model.BoxMax().z()}
                                        : storeys[StoreyAt(storeys, z_)];
  const double top_limit =
      std::min(storey.floor_z + options.max_obstacle_top, storey.top_z - kTopBelowCeiling);
  // Largest first: a cell's enclosing cell is larger than the cell.
  for (int k = static_cast<int>(cells_.size()) - 1; k >= 0; --k) {
    SectionCell& cell = cells_[k];
    const int around = enclosing_of_component_[cell.component];
    const bool free = around < 0 || cells_[around].kind != SpaceKind::kFree;
    cell.kind = free ? SpaceKind::kFree : SpaceKind::kSolid;
    cell.solid_reason = free ? SolidReason::kNone : SolidReason::kNested;
    if (!free) continue;
    const std::vector<Ring2> holes = NestedFootprints(k);
    double area = cell.area;
    for (const Ring2& hole : holes)
      area -= RingSignedArea(hole);
    if (!FindWidePoint(cell.ring, holes, options.min_free_half_width, &cell.wide_point)) {
      cell.kind = SpaceKind::kSolid;
      cell.solid_reason = SolidReason::kNarrow;
      continue;
    }
    for (const HorizontalFace& top : tops) {
      if (top.z <= z_ + kBand || top.z > top_limit || top.area < kTopCoverShare * area) continue;
      if (RingContains(top.ring, cell.wide_point)) {
        cell.kind = SpaceKind::kSolid;
        cell.solid_reason = SolidReason::kTopped;
        break;
      }
    }
  }
}

int PlanSection::CellAt(const Eigen::Vector2d& p) const {
  for (size_t k = 0; k < cells_.size(); ++k) {
    const SectionCell& cell = cells_[k];
    if ((p.array() < cell.lo.array()).any() || (p.array() > cell.hi.array()).any()) continue;
    if (RingContains(cell.ring, p)) return static_cast<int>(k);
  }
  return -1;
}

SpaceAt PlanSection::Classify(const Eigen::Vector2d& p) const {
  const int cell = CellAt(p);
  if (cell < 0) return {};
  return {cells_[cell].kind, cells_[cell].solid_reason};
}

FreeSpace::FreeSpace(const WireframeModel& model, const FreeSpaceOptions& options)
    : model_(model), options_(options) {
  for (const ModelFace& face : model.faces()) {
    if (!face.vertical || face.Degenerate()) continue;
    for (const Eigen::Vector3d& c : face.corners)
      events_.push_back(c.z());
  }
  std::sort(events_.begin(), events_.end());
  events_.erase(std::unique(events_.begin(), events_.end(),
                            [](double a, double b) { return b - a < kEventTolerance; }),
                events_.end());
}

FreeSpace::~FreeSpace() = default;

const PlanSection& FreeSpace::SectionAt(double z) {
  // Between two heights where faces start, end or turn, the section keeps its walls: one section
  // per band, cut at its middle.
  const long band = std::upper_bound(events_.begin(), events_.end(), z) - events_.begin();
  auto it = sections_.find(band);
  if (it == sections_.end()) {
    const long n = static_cast<long>(events_.size());
    const double cut = n == 0      ? z
                       : band == 0 ? events_.front() - 1.0
                       : band == n ? events_.back() + 1.0
                                   : 0.5 * (events_[band - 1] + events_[band]);
    it =
        sections_
            .emplace(band, std::make_unique<PlanSection>(PlanSection::Build(model_, cut, options_)))
            .first;
  }
  return *it->second;
}

SpaceAt FreeSpace::Classify(const Eigen::Vector3d& p) {
  const std::vector<Storey>& storeys = model_.storeys();
  if (storeys.empty()) return SectionAt(p.z()).Classify(p.head<2>());
  size_t s = 0;
  while (s + 1 < storeys.size() && storeys[s + 1].floor_z <= p.z())
    ++s;
  const Storey& storey = storeys[s];
  if (p.z() > storey.top_z && s + 1 < storeys.size() && p.z() < storeys[s + 1].floor_z) {
    // The slab between two storeys: solid over the lower storey's cells.
    const SpaceAt below = SectionAt(NavigationHeight(storey, options_)).Classify(p.head<2>());
    if (below.kind == SpaceKind::kOutside) return below;
    return {SpaceKind::kSolid, SolidReason::kSlab};
  }
  return SectionAt(p.z()).Classify(p.head<2>());
}

}  // namespace linetrack
