#include "models/navigable_area.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "models/errors.h"

namespace linetrack {
namespace {

double DistanceToSegment(const Eigen::Vector2d& p, const Segment2& s) {
  const Eigen::Vector2d d = s.b - s.a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - s.a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (s.a + t * d - p).norm();
}

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

// Floor-plan segments of the model's vertical faces (the walls a camera keeps away from).
std::vector<Segment2> WallSegments(const WireframeModel& model) {
  std::vector<Segment2> walls;
  for (const ModelFace& face : model.faces()) {
    if (!face.vertical) continue;
    // The plan footprint of a vertical face is the segment between its extreme corners along
    // the horizontal direction of its plane.
    const Eigen::Vector2d along(-face.normal.y(), face.normal.x());
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();
    for (const Eigen::Vector3d& c : face.corners) {
      const double s = along.dot(c.head<2>());
      if (s < lo) lo = s, a = c.head<2>();
      if (s > hi) hi = s, b = c.head<2>();
    }
    if (hi - lo > 1e-9) walls.push_back({a, b});
  }
  return walls;
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
  double twice = 0.0;
  for (size_t i = 0; i < vertices.size(); ++i) {
    twice += Cross2(vertices[i], vertices[(i + 1) % vertices.size()]);
  }
  return 0.5 * twice;
}

bool Polygon2::Contains(const Eigen::Vector2d& p) const {
  bool inside = false;
  for (size_t i = 0, j = vertices.size() - 1; i < vertices.size(); j = i++) {
    const Eigen::Vector2d& a = vertices[i];
    const Eigen::Vector2d& b = vertices[j];
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      const double x = a.x() + (p.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
      if (p.x() < x) inside = !inside;
    }
  }
  return inside;
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
  throw InputError(Located(model.path(), 0,
                           "no navigable-area file next to the model (derivation from the walls "
                           "is not implemented yet)"));
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
