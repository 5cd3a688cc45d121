// The navigable area: where the robot's camera can be on the floor plane (world x, y, metres).
// By default the floor footprint enclosed by the model's wall faces, minus obstacles (pillars,
// partition walls) and a clearance; optionally a polygon from a sidecar file next to the model.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "models/geometry.h"
#include "models/wireframe.h"

namespace linetrack {

// A simple polygon in the floor plane, counter-clockwise, not closed (last != first).
struct Polygon2 {
  std::vector<Eigen::Vector2d> vertices;

  double SignedArea() const;                      // > 0 when counter-clockwise
  bool Contains(const Eigen::Vector2d& p) const;  // crossing-number test
};

struct NavigableAreaOptions {
  // Minimum distance (metres) from any wall or obstacle face for a camera position.
  double clearance = 0.3;
  // Sidecar polygon file; empty: "<model without .cao>.nav.json" when it exists.
  // Format: {"outer": [[x, y], ...], "holes": [[[x, y], ...], ...], "clearance": 0.3}
  // ("holes" and "clearance" optional; "clearance" overrides the option above).
  std::string sidecar_path;

  bool Check(std::string* why) const;
};

class NavigableArea {
 public:
  // From the sidecar file when present, else derived from the wall faces (see docs/models.md).
  // Throws InputError naming the sidecar or model file when neither gives an area.
  static NavigableArea FromModel(const WireframeModel& model,
                                 const NavigableAreaOptions& options = {});

  // An explicit area: `outer` boundary, `holes` (obstacle footprints), `walls` (floor-plan
  // segments the clearance keeps away from).
  static NavigableArea FromPolygons(Polygon2 outer, std::vector<Polygon2> holes,
                                    std::vector<Segment2> walls, double clearance,
                                    std::string source);

  // True when p is inside the outer boundary, outside every hole, and at least `clearance`
  // from every wall segment.
  bool Contains(const Eigen::Vector2d& p) const;
  // Inside the outer boundary, outside every hole, and at least `margin` metres from every wall
  // segment (a smaller clearance than Contains uses).
  bool InsideWalls(const Eigen::Vector2d& p, double margin = 0.0) const;

  const Polygon2& outer() const { return outer_; }
  const std::vector<Polygon2>& holes() const { return holes_; }
  const std::vector<Segment2>& walls() const { return walls_; }
  double clearance() const { return clearance_; }
  // Outer area minus holes (m^2), ignoring the clearance band.
  double Area() const;
  // Where the area came from, for reports: e.g. "sidecar hall.nav.json" or "walls (4 faces)".
  const std::string& source() const { return source_; }
  Eigen::Vector2d BoundsMin() const;
  Eigen::Vector2d BoundsMax() const;

 private:
  Polygon2 outer_;
  std::vector<Polygon2> holes_;
  std::vector<Segment2> walls_;
  double clearance_ = 0.0;
  std::string source_;
};

}  // namespace linetrack
