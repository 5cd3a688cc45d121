#include "models/navigable_area.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "models/convex_polygon.h"
#include "models/errors.h"
#include "models/free_space.h"
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

// One part of a sidecar file: "outer", optional "holes" and "storey" (fields named with `prefix`).
AreaPart ReadPart(const nlohmann::json& doc, const std::string& path, const std::string& prefix,
                  int num_storeys) {
  if (!doc.is_object() || !doc.contains("outer")) {
    throw InputError(Located(path, 0, prefix + "outer: expected an \"outer\" polygon"));
  }
  AreaPart part;
  part.outer = ReadRing(doc["outer"], path, prefix + "outer");
  if (doc.contains("holes")) {
    if (!doc["holes"].is_array()) {
      throw InputError(Located(path, 0, prefix + "holes must be an array"));
    }
    for (size_t i = 0; i < doc["holes"].size(); ++i) {
      part.holes.push_back(
          ReadRing(doc["holes"][i], path, prefix + "holes[" + std::to_string(i) + "]"));
    }
  }
  if (doc.contains("storey")) {
    if (!doc["storey"].is_number_integer() || doc["storey"].get<int>() < 0 ||
        doc["storey"].get<int>() >= num_storeys) {
      throw InputError(Located(path, 0,
                               prefix + "storey must be an integer in [0, " +
                                   std::to_string(num_storeys) + ") (the model's storeys)"));
    }
    part.storey = doc["storey"].get<int>();
  }
  return part;
}

// Points closer than this are one (metres), and faces smaller than this have no area (m^2).
constexpr double kPlanTolerance = 1e-6;
constexpr double kMinFootprintArea = 1e-6;
// Margin around the model's plan when no walls enclose it (metres).
constexpr double kOpenModelMargin = 2.0;
// Cells of the wall index (metres).
constexpr double kWallCell = 1.0;

Polygon2 CounterClockwise(Ring2 ring) {
  if (RingSignedArea(ring) < 0.0) std::reverse(ring.begin(), ring.end());
  return Polygon2{std::move(ring)};
}

int NumWallFaces(const WireframeModel& model) {
  int n = 0;
  for (const ModelFace& face : model.faces())
    n += face.vertical && !face.Degenerate() ? 1 : 0;
  return n;
}

// Each storey's wall spans at its navigation height.
std::vector<std::vector<Segment2>> StoreyWalls(const WireframeModel& model, FreeSpace* space) {
  std::vector<std::vector<Segment2>> walls;
  for (const Storey& storey : model.storeys())
    walls.push_back(space->SectionAt(NavigationHeight(storey, space->options())).walls());
  return walls;
}

// The free cells of each storey's navigation section, with the solids nested in them as holes;
// without any, the model's plan bounding box grown by kOpenModelMargin minus the closed
// footprints of the lowest storey.
NavigableArea DeriveFromWalls(const WireframeModel& model, double clearance) {
  if (model.vertices().empty()) {
    throw InputError(Located(model.path(), 0, "the model has no points: no navigable area"));
  }
  FreeSpace space(model);
  std::vector<AreaPart> parts;
  for (size_t s = 0; s < model.storeys().size(); ++s) {
    const PlanSection& nav = space.SectionAt(NavigationHeight(model.storeys()[s], space.options()));
    for (size_t k = 0; k < nav.cells().size(); ++k) {
      if (nav.cells()[k].kind != SpaceKind::kFree) continue;
      AreaPart part;
      part.outer = CounterClockwise(SimplifyRing(nav.cells()[k].ring, kPlanTolerance));
      if (part.outer.vertices.size() < 3 || part.outer.SignedArea() < kMinFootprintArea) continue;
      for (Ring2& hole : nav.NestedFootprints(static_cast<int>(k)))
        part.holes.push_back(CounterClockwise(std::move(hole)));
      part.storey = static_cast<int>(s);
      parts.push_back(std::move(part));
    }
  }
  std::string source = "walls (" + std::to_string(NumWallFaces(model)) + " faces)";
  if (parts.empty()) {
    const Eigen::Vector2d lo =
        model.BoxMin().head<2>() - Eigen::Vector2d::Constant(kOpenModelMargin);
    const Eigen::Vector2d hi =
        model.BoxMax().head<2>() + Eigen::Vector2d::Constant(kOpenModelMargin);
    AreaPart part;
    part.outer.vertices = {lo, {hi.x(), lo.y()}, hi, {lo.x(), hi.y()}};
    const PlanSection& nav =
        space.SectionAt(NavigationHeight(model.storeys().front(), space.options()));
    for (Ring2& footprint : nav.NestedFootprints(-1))
      part.holes.push_back(CounterClockwise(std::move(footprint)));
    parts.push_back(std::move(part));
    source = "bounding box + 2 m (no enclosing walls)";
  }
  return NavigableArea::FromParts(std::move(parts), StoreyWalls(model, &space), model.storeys(),
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
  if (!doc.is_object() || !(doc.contains("outer") || doc.contains("parts"))) {
    throw InputError(Located(path, 0, "expected an object with an \"outer\" polygon or \"parts\""));
  }
  std::vector<AreaPart> parts;
  if (doc.contains("parts")) {
    if (!doc["parts"].is_array() || doc["parts"].empty()) {
      throw InputError(Located(path, 0, "\"parts\" must be a non-empty array"));
    }
    for (size_t i = 0; i < doc["parts"].size(); ++i) {
      parts.push_back(ReadPart(doc["parts"][i], path, "parts[" + std::to_string(i) + "].",
                               static_cast<int>(model.storeys().size())));
    }
  } else {
    parts.push_back(ReadPart(doc, path, "", static_cast<int>(model.storeys().size())));
  }
  double clearance = default_clearance;
  if (doc.contains("clearance")) {
    if (!doc["clearance"].is_number() || !(doc["clearance"].get<double>() >= 0.0)) {
      throw InputError(Located(path, 0, "\"clearance\" must be a number >= 0 (metres)"));
    }
    clearance = doc["clearance"].get<double>();
  }
  FreeSpace space(model);
  return NavigableArea::FromParts(std::move(parts), StoreyWalls(model, &space), model.storeys(),
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

// Wall segments in a uniform grid, for "is p within margin of a wall?".
struct NavigableArea::WallIndex {
  std::vector<Segment2> walls;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  int cols = 0, rows = 0;
  std::vector<std::vector<int>> cells;

  explicit WallIndex(std::vector<Segment2> segments) : walls(std::move(segments)) {
    if (walls.empty()) return;
    Eigen::Vector2d lo = walls.front().a, hi = lo;
    for (const Segment2& w : walls) {
      lo = lo.cwiseMin(w.a).cwiseMin(w.b);
      hi = hi.cwiseMax(w.a).cwiseMax(w.b);
    }
    origin = lo;
    cols = static_cast<int>(std::floor((hi.x() - lo.x()) / kWallCell)) + 1;
    rows = static_cast<int>(std::floor((hi.y() - lo.y()) / kWallCell)) + 1;
    cells.assign(static_cast<size_t>(cols) * rows, {});
    for (size_t i = 0; i < walls.size(); ++i) {
      const Eigen::Vector2d a = walls[i].a.cwiseMin(walls[i].b);
      const Eigen::Vector2d b = walls[i].a.cwiseMax(walls[i].b);
      for (int r = Row(a.y()); r <= Row(b.y()); ++r) {
        for (int c = Col(a.x()); c <= Col(b.x()); ++c)
          cells[static_cast<size_t>(r) * cols + c].push_back(static_cast<int>(i));
      }
    }
  }
  int Col(double x) const {
    return std::clamp(static_cast<int>(std::floor((x - origin.x()) / kWallCell)), 0, cols - 1);
  }
  int Row(double y) const {
    return std::clamp(static_cast<int>(std::floor((y - origin.y()) / kWallCell)), 0, rows - 1);
  }
  bool Near(const Eigen::Vector2d& p, double margin) const {
    if (walls.empty() || margin <= 0.0) return false;
    for (int r = Row(p.y() - margin); r <= Row(p.y() + margin); ++r) {
      for (int c = Col(p.x() - margin); c <= Col(p.x() + margin); ++c) {
        for (int i : cells[static_cast<size_t>(r) * cols + c]) {
          if (DistanceToSegment(p, walls[i]) < margin) return true;
        }
      }
    }
    return false;
  }
};

NavigableArea NavigableArea::FromPolygons(Polygon2 outer, std::vector<Polygon2> holes,
                                          std::vector<Segment2> walls, double clearance,
                                          std::string source) {
  std::vector<AreaPart> parts(1);
  parts[0].outer = std::move(outer);
  parts[0].holes = std::move(holes);
  return FromParts(std::move(parts), {std::move(walls)}, {Storey{}}, clearance, std::move(source));
}

NavigableArea NavigableArea::FromParts(std::vector<AreaPart> parts,
                                       std::vector<std::vector<Segment2>> walls,
                                       std::vector<Storey> storeys, double clearance,
                                       std::string source) {
  NavigableArea area;
  area.parts_ = std::move(parts);
  area.storeys_ = std::move(storeys);
  walls.resize(std::max(walls.size(), area.storeys_.size()));
  for (std::vector<Segment2>& storey_walls : walls) {
    area.all_walls_.insert(area.all_walls_.end(), storey_walls.begin(), storey_walls.end());
    area.walls_.push_back(std::make_shared<const WallIndex>(std::move(storey_walls)));
  }
  for (const AreaPart& part : area.parts_) {
    Eigen::Vector2d lo = part.outer.vertices.front(), hi = lo;
    for (const Eigen::Vector2d& v : part.outer.vertices)
      lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    area.part_lo_.push_back(lo);
    area.part_hi_.push_back(hi);
  }
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

bool NavigableArea::InPart(const AreaPart& part, const Eigen::Vector2d& p) const {
  if (!part.outer.Contains(p)) return false;
  for (const Polygon2& hole : part.holes) {
    if (hole.Contains(p)) return false;
  }
  return true;
}

bool NavigableArea::NearWall(int storey, const Eigen::Vector2d& p, double margin) const {
  return storey >= 0 && storey < static_cast<int>(walls_.size()) && walls_[storey]->Near(p, margin);
}

bool NavigableArea::InsideWalls(const Eigen::Vector2d& p, double margin, int storey) const {
  for (size_t i = 0; i < parts_.size(); ++i) {
    const AreaPart& part = parts_[i];
    if ((storey >= 0 && part.storey != storey) || (p.array() < part_lo_[i].array()).any() ||
        (p.array() > part_hi_[i].array()).any() || !InPart(part, p)) {
      continue;
    }
    if (!NearWall(part.storey, p, margin)) return true;
  }
  return false;
}

bool NavigableArea::InsideBoundary(const Eigen::Vector2d& p, int storey) const {
  return InsideWalls(p, 0.0, storey);
}

bool NavigableArea::Contains(const Eigen::Vector2d& p, int storey) const {
  return InsideWalls(p, clearance_, storey);
}

double NavigableArea::Area(int storey) const {
  double area = 0.0;
  for (const AreaPart& part : parts_) {
    if (storey >= 0 && part.storey != storey) continue;
    area += std::abs(part.outer.SignedArea());
    for (const Polygon2& hole : part.holes)
      area -= std::abs(hole.SignedArea());
  }
  return area;
}

Eigen::Vector2d NavigableArea::BoundsMin(int storey) const {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < parts_.size(); ++i) {
    if (storey < 0 || parts_[i].storey == storey) lo = lo.cwiseMin(part_lo_[i]);
  }
  return lo.allFinite() || storey < 0 ? lo : BoundsMin(-1);
}

Eigen::Vector2d NavigableArea::BoundsMax(int storey) const {
  Eigen::Vector2d hi = Eigen::Vector2d::Constant(-std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < parts_.size(); ++i) {
    if (storey < 0 || parts_[i].storey == storey) hi = hi.cwiseMax(part_hi_[i]);
  }
  return hi.allFinite() || storey < 0 ? hi : BoundsMax(-1);
}

}  // namespace linetrack
