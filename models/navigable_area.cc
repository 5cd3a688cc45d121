#include "models/navigable_area.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "models/convex_polygon.h"
#include "models/errors.h"
#include "models/plan_arrangement.h"

namespace linetrack {
namespace {

Polygon2 ReadRing(const nlohmann::json& ring, const std::string& path, const std::string& field) {
  if (!ring.is_array() || ring.size() < 3) {
    throw InputError(Located(path, 0, field + " must be an array of at least 3 [x, y] points"));
  }
  Polygon2 polygon;
  for (const auto& point : ring) {
    if (!point.is_array() || point.size() != 2 || !point[0].is_number() || !point[1].is_number()) {
      throw InputError(Located(path, 0, field + ": every point must be [x, y] in metres"));
    }
    const Eigen::Vector2d p(point[0].get<double>(), point[1].get<double>());
    if (!p.allFinite()) throw InputError(Located(path, 0, field + ": coordinates must be finite"));
    polygon.vertices.push_back(p);
  }
  if (std::abs(polygon.SignedArea()) < 1e-9) {
    throw InputError(Located(path, 0, field + ": the polygon has no area"));
  }
  if (polygon.SignedArea() < 0.0) std::reverse(polygon.vertices.begin(), polygon.vertices.end());
  return polygon;
}

// Floor-plan footprints of the model's vertical faces (the walls), with the side they face.
std::vector<PlanWall> PlanWalls(const WireframeModel& model) {
  std::vector<PlanWall> walls;
  for (const ModelFace& face : model.faces()) {
    if (!face.vertical || face.Degenerate()) continue;
    // The footprint of a vertical face is the segment between its extreme corners along the
    // horizontal direction of its plane.
    const Eigen::Vector2d normal = face.normal.head<2>().normalized();
    const Eigen::Vector2d along(-normal.y(), normal.x());
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();
    for (const Eigen::Vector3d& c : face.corners) {
      const double s = along.dot(c.head<2>());
      if (s < lo) lo = s, a = c.head<2>();
      if (s > hi) hi = s, b = c.head<2>();
    }
    if (hi - lo > 1e-9) walls.push_back({{a, b}, normal});
  }
  return walls;
}

std::vector<Segment2> WallSegments(const WireframeModel& model) {
  std::vector<Segment2> segments;
  for (const PlanWall& wall : PlanWalls(model))
    segments.push_back(wall.segment);
  return segments;
}

// Footprints closer than this merge (metres), and faces smaller than this have no area (m^2).
constexpr double kPlanTolerance = 1e-6;
constexpr double kMinFootprintArea = 1e-6;
// Margin around the model's plan when no walls enclose it (metres).
constexpr double kOpenModelMargin = 2.0;

Polygon2 CounterClockwise(Ring2 ring) {
  if (RingSignedArea(ring) < 0.0) std::reverse(ring.begin(), ring.end());
  return Polygon2{std::move(ring)};
}

// The outer boundary: the largest bounded face of the wall arrangement whose walls mostly face
// into it (a room's walls face inwards); nullptr when no such face exists.
const PlanCycle* Enclosure(const PlanArrangement& walls) {
  const PlanCycle* best = nullptr;
  for (const PlanCycle& cycle : walls.cycles()) {
    if (cycle.signed_area <= kMinFootprintArea || cycle.facing_length <= 0.5 * cycle.length) {
      continue;
    }
    if (best == nullptr || cycle.signed_area > best->signed_area) best = &cycle;
  }
  return best;
}

// Obstacles inside `outer`: the footprints of the closed wall loops not connected to the outer
// boundary (pillars, free-standing boxes), outermost first, nested ones dropped.
std::vector<Polygon2> ClosedFootprintsInside(const PlanArrangement& walls, const Polygon2& outer,
                                             int outer_component) {
  std::vector<Polygon2> footprints;
  for (const PlanCycle& cycle : walls.cycles()) {
    // A component's outer boundary is its one clockwise cycle.
    if (cycle.signed_area >= -kMinFootprintArea || cycle.component == outer_component) continue;
    Polygon2 footprint = CounterClockwise(walls.CycleRing(cycle));
    if (footprint.vertices.size() < 3 || footprint.SignedArea() < kMinFootprintArea) continue;
    if (outer.Contains(footprint.vertices.front())) footprints.push_back(std::move(footprint));
  }
  std::sort(footprints.begin(), footprints.end(),
            [](const Polygon2& a, const Polygon2& b) { return a.SignedArea() > b.SignedArea(); });
  std::vector<Polygon2> holes;
  for (Polygon2& footprint : footprints) {
    const bool nested = std::any_of(holes.begin(), holes.end(), [&](const Polygon2& hole) {
      return hole.Contains(footprint.vertices.front());
    });
    if (!nested) holes.push_back(std::move(footprint));
  }
  return holes;
}

// The floor enclosed by the walls minus the closed obstacles in it; without enclosing walls the
// model's plan bounding box grown by kOpenModelMargin, minus the closed footprints.
NavigableArea DeriveFromWalls(const WireframeModel& model, double clearance) {
  if (model.vertices().empty()) {
    throw InputError(Located(model.path(), 0, "the model has no points: no navigable area"));
  }
  const std::vector<PlanWall> plan_walls = PlanWalls(model);
  const PlanArrangement walls = PlanArrangement::Build(plan_walls, kPlanTolerance);
  const PlanCycle* enclosure = Enclosure(walls);
  Polygon2 outer;
  std::string source;
  int outer_component = -1;
  if (enclosure != nullptr) {
    outer = CounterClockwise(walls.CycleRing(*enclosure));
    outer_component = enclosure->component;
    source = "walls (" + std::to_string(plan_walls.size()) + " faces)";
  }
  if (outer.vertices.size() < 3) {
    const Eigen::Vector2d lo =
        model.BoxMin().head<2>() - Eigen::Vector2d::Constant(kOpenModelMargin);
    const Eigen::Vector2d hi =
        model.BoxMax().head<2>() + Eigen::Vector2d::Constant(kOpenModelMargin);
    outer.vertices = {lo, {hi.x(), lo.y()}, hi, {lo.x(), hi.y()}};
    outer_component = -1;
    source = "bounding box + 2 m (no enclosing walls)";
  }
  std::vector<Polygon2> holes = ClosedFootprintsInside(walls, outer, outer_component);
  std::vector<Segment2> segments;
  for (const PlanWall& wall : plan_walls)
    segments.push_back(wall.segment);
  return NavigableArea::FromPolygons(std::move(outer), std::move(holes), std::move(segments),
                                     clearance, source);
}

NavigableArea FromSidecar(const WireframeModel& model, const std::string& path,
                          double default_clearance) {
  std::ifstream in(path);
  if (!in) throw InputError(Located(path, 0, "cannot read the navigable-area file"));
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(Located(path, 0, std::string("not valid JSON: ") + e.what()));
  }
  if (!doc.is_object() || !doc.contains("outer")) {
    throw InputError(Located(path, 0, "expected an object with an \"outer\" polygon"));
  }
  Polygon2 outer = ReadRing(doc["outer"], path, "outer");
  std::vector<Polygon2> holes;
  if (doc.contains("holes")) {
    if (!doc["holes"].is_array()) throw InputError(Located(path, 0, "\"holes\" must be an array"));
    for (size_t i = 0; i < doc["holes"].size(); ++i) {
      holes.push_back(ReadRing(doc["holes"][i], path, "holes[" + std::to_string(i) + "]"));
    }
  }
  double clearance = default_clearance;
  if (doc.contains("clearance")) {
    if (!doc["clearance"].is_number() || !(doc["clearance"].get<double>() >= 0.0)) {
      throw InputError(Located(path, 0, "\"clearance\" must be a number >= 0 (metres)"));
    }
    clearance = doc["clearance"].get<double>();
  }
  return NavigableArea::FromPolygons(std::move(outer), std::move(holes), WallSegments(model),
                                     clearance,
                                     "sidecar " + std::filesystem::path(path).filename().string());
}

}  // namespace

double Polygon2::SignedArea() const {
  return RingSignedArea(vertices);
}

bool Polygon2::Contains(const Eigen::Vector2d& p) const {
  return RingContains(vertices, p);
}

bool NavigableAreaOptions::Check(std::string* why) const {
  if (!(clearance >= 0.0 && clearance < 10.0)) {
    *why = "clearance must be in [0, 10) metres";
    return false;
  }
  return true;
}

NavigableArea NavigableArea::FromPolygons(Polygon2 outer, std::vector<Polygon2> holes,
                                          std::vector<Segment2> walls, double clearance,
                                          std::string source) {
  NavigableArea area;
  area.outer_ = std::move(outer);
  area.holes_ = std::move(holes);
  area.walls_ = std::move(walls);
  area.clearance_ = clearance;
  area.source_ = std::move(source);
  return area;
}

NavigableArea NavigableArea::FromModel(const WireframeModel& model,
                                       const NavigableAreaOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError(Located(model.path(), 0, why));
  std::string sidecar = options.sidecar_path;
  if (sidecar.empty()) {
    std::filesystem::path p(model.path());
    const std::filesystem::path candidate = p.replace_extension(".nav.json");
    std::error_code ec;
    if (std::filesystem::exists(candidate, ec)) sidecar = candidate.string();
  }
  if (!sidecar.empty()) return FromSidecar(model, sidecar, options.clearance);
  return DeriveFromWalls(model, options.clearance);
}

bool NavigableArea::InsideWalls(const Eigen::Vector2d& p, double margin) const {
  if (!outer_.Contains(p)) return false;
  for (const Polygon2& hole : holes_) {
    if (hole.Contains(p)) return false;
  }
  for (const Segment2& wall : walls_) {
    if (DistanceToSegment(p, wall) < margin) return false;
  }
  return true;
}

bool NavigableArea::Contains(const Eigen::Vector2d& p) const {
  return InsideWalls(p, clearance_);
}

double NavigableArea::Area() const {
  double area = std::abs(outer_.SignedArea());
  for (const Polygon2& hole : holes_)
    area -= std::abs(hole.SignedArea());
  return area;
}

Eigen::Vector2d NavigableArea::BoundsMin() const {
  Eigen::Vector2d lo = outer_.vertices.front();
  for (const Eigen::Vector2d& v : outer_.vertices)
    lo = lo.cwiseMin(v);
  return lo;
}

Eigen::Vector2d NavigableArea::BoundsMax() const {
  Eigen::Vector2d hi = outer_.vertices.front();
  for (const Eigen::Vector2d& v : outer_.vertices)
    hi = hi.cwiseMax(v);
  return hi;
}

}  // namespace linetrack
