// The navigable area: where the robot's camera can be on the floor plane (world x, y, metres), per
// storey. By default every space the model's walls enclose (rooms and corridors, joined by door
// openings or separate), minus obstacles (pillars, boxes) and a clearance; optionally polygons from
// a sidecar file next to the model.
#pragma once

#include <Eigen/Core>
#include <memory>
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

// One connected part of the navigable area on one storey: an outer boundary and its holes.
struct AreaPart {
  Polygon2 outer;
  std::vector<Polygon2> holes;
  int storey = 0;  // index into the model's storeys()
};

struct NavigableAreaOptions {
  // Minimum distance (metres) from any wall or obstacle face for a camera position.
  double clearance = 0.3;
  // Sidecar polygon file; empty: "<model without .cao>.nav.json" when it exists.
  // Format: {"outer": [[x, y], ...], "holes": [[[x, y], ...], ...], "clearance": 0.3}
  // ("holes" and "clearance" optional; "clearance" overrides the option above), or several parts:
  // {"parts": [{"outer": ..., "holes": ..., "storey": 1}, ...], "clearance": 0.3}.
  std::string sidecar_path;

  bool Check(std::string* why) const;
};

class NavigableArea {
 public:
  // From the sidecar file when present, else derived from the walls (see docs/models.md): the
  // free cells of each storey's navigation section (models/free_space.h). Throws InputError
  // naming the sidecar or model file when neither gives an area.
  static NavigableArea FromModel(const WireframeModel& model,
                                 const NavigableAreaOptions& options = {});

  // An explicit one-storey area: `outer` boundary, `holes` (obstacle footprints), `walls`
  // (floor-plan segments the clearance keeps away from).
  static NavigableArea FromPolygons(Polygon2 outer, std::vector<Polygon2> holes,
                                    std::vector<Segment2> walls, double clearance,
                                    std::string source);

  // An explicit area of several parts; `walls[s]` are storey s's wall segments, `storeys` the
  // model's (one entry per storey a part or wall list refers to).
  static NavigableArea FromParts(std::vector<AreaPart> parts,
                                 std::vector<std::vector<Segment2>> walls,
                                 std::vector<Storey> storeys, double clearance, std::string source);

  // True when p is inside a part's outer boundary, outside its holes, and at least `clearance`
  // from every wall segment of that part's storey; `storey` < 0: on any storey.
  bool Contains(const Eigen::Vector2d& p, int storey = -1) const;
  // Inside a part, outside its holes, and at least `margin` metres from every wall segment of its
  // storey (a smaller clearance than Contains uses); `storey` < 0: on any storey.
  bool InsideWalls(const Eigen::Vector2d& p, double margin = 0.0, int storey = -1) const;
  // Inside a part and outside its holes, whatever the walls; `storey` < 0: on any storey.
  bool InsideBoundary(const Eigen::Vector2d& p, int storey = -1) const;

  const std::vector<AreaPart>& parts() const { return parts_; }
  // The storeys the parts stand on (the model's).
  const std::vector<Storey>& storeys() const { return storeys_; }
  // Wall segments of every storey.
  const std::vector<Segment2>& walls() const { return all_walls_; }
  double clearance() const { return clearance_; }
  // Outer areas minus holes (m^2) of the parts (of one storey when `storey` >= 0), ignoring the
  // clearance band.
  double Area(int storey = -1) const;
  // Where the area came from, for reports: e.g. "sidecar hall.nav.json" or "walls (4 faces)".
  const std::string& source() const { return source_; }
  // Bounds of all parts (of one storey when `storey` >= 0 and it has parts).
  Eigen::Vector2d BoundsMin(int storey = -1) const;
  Eigen::Vector2d BoundsMax(int storey = -1) const;

 private:
  struct WallIndex;
  bool InPart(const AreaPart& part, const Eigen::Vector2d& p) const;
  bool NearWall(int storey, const Eigen::Vector2d& p, double margin) const;

  std::vector<AreaPart> parts_;
  std::vector<Eigen::Vector2d> part_lo_, part_hi_;  // bounding boxes of the parts
  std::vector<Storey> storeys_;
  std::vector<std::shared_ptr<const WallIndex>> walls_;  // per storey
  std::vector<Segment2> all_walls_;
  double clearance_ = 0.0;
  std::string source_;
};

}  // namespace linetrack
