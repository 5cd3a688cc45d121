// The planar arrangement of wall footprints: floor-plan segments split where they meet, coincident
// pieces merged, and the boundary cycles of the faces they bound (half-edge traversal with the
// face on the left). Used to derive the navigable area and the solid obstacles of the VIRs.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "models/convex_polygon.h"
#include "models/geometry.h"

namespace linetrack {

// A wall seen from above: its floor-plan segment and the unit normal of the side from which it is
// visible (ViSP's face orientation); a zero normal when that is unknown.
struct PlanWall {
  Segment2 segment;
  Eigen::Vector2d normal = Eigen::Vector2d::Zero();
};

// One boundary cycle of the arrangement, the face it bounds on its left.
struct PlanCycle {
  std::vector<int> vertices;  // arrangement vertex ids in walking order
  double signed_area = 0.0;   // > 0: the outer boundary of a bounded face (counter-clockwise)
  int component = -1;         // connected component of the walls
  double length = 0.0;        // metres
  // Length of the boundary whose walls face the face on the left (e.g. a room's walls seen from
  // inside the room; a pillar's walls seen from outside it).
  double facing_length = 0.0;
};

class PlanArrangement {
 public:
  // Splits the walls where they cross or touch and merges pieces closer than `tolerance` metres.
  static PlanArrangement Build(const std::vector<PlanWall>& walls, double tolerance);

  const std::vector<Eigen::Vector2d>& vertices() const { return vertices_; }
  // Pieces as vertex pairs (first < second).
  const std::vector<std::array<int, 2>>& edges() const { return edges_; }
  const std::vector<PlanCycle>& cycles() const { return cycles_; }
  int num_components() const { return num_components_; }
  // Vertices joined to `vertex` by an edge.
  const std::vector<int>& Neighbours(int vertex) const { return neighbours_[vertex]; }
  // The points of a cycle, spikes (dangling walls) and straight-through vertices removed.
  Ring2 CycleRing(const PlanCycle& cycle) const;

 private:
  std::vector<Eigen::Vector2d> vertices_;
  std::vector<std::array<int, 2>> edges_;
  // Per edge: a wall faces the left / right side of first -> second.
  std::vector<std::array<bool, 2>> faced_;
  std::vector<std::vector<int>> neighbours_;
  std::vector<PlanCycle> cycles_;
  int num_components_ = 0;
  double tolerance_ = 0.0;
};

}  // namespace linetrack
