// Where a model's free space lies, decided from its geometry alone (never from the orientation of
// its faces): the storeys, the plan sections of the walls at a height, and the cells of a section
// classified as free (rooms, corridors), solid (pillars, boxes, the inside of thick walls) or
// outside. Face orientation and the navigable area are built on it (docs/models.md).
#pragma once

#include <Eigen/Core>
#include <map>
#include <memory>
#include <vector>

#include "models/convex_polygon.h"
#include "models/plan_arrangement.h"
#include "models/wireframe.h"

namespace linetrack {

// Storeys from the vertical faces: the bottoms of walls cluster at each floor height; a cluster is
// a new storey when it lies at or above the top of the storey below and its walls are at least
// kMinStoreyHeightM tall. One storey (the model's z range) when there are no vertical faces.
std::vector<Storey> DetectStoreys(const std::vector<ModelFace>& faces, double z_min, double z_max);

// Index of the storey a world height z belongs to: the highest whose floor is at or below z
// (0 below every floor).
int StoreyAt(const std::vector<Storey>& storeys, double z);

// What a point of space is.
enum class SpaceKind { kOutside = 0, kSolid = 1, kFree = 2 };

// Why a cell is solid.
enum class SolidReason {
  kNone,    // the cell is free
  kNested,  // inside a free cell of another component (a pillar, a free-standing box)
  kNarrow,  // too narrow for the camera (the inside of a thick wall, a thin partition)
  kTopped,  // under a horizontal face below the ceiling (a cabinet with its top)
  kSlab,    // between two storeys, above the lower one's cells
};

// The space at a point: its kind, and for a solid why.
struct SpaceAt {
  SpaceKind kind = SpaceKind::kOutside;
  SolidReason solid_reason = SolidReason::kNone;
};

// Thresholds of the classification (metres).
struct FreeSpaceOptions {
  // A free cell must hold a disk of this radius (narrower cells are solid: the inside of a thick
  // wall, a thin partition).
  double min_free_half_width = 0.2;
  // A cell under a horizontal face lower than the storey's floor + this (and below its ceiling)
  // is the body of a box (a cabinet with its top).
  double max_obstacle_top = 2.2;
  // The section used for the navigable area lies this far above each storey's floor.
  double navigation_height = 0.25;
};

// Height of a storey's navigation section: floor + navigation_height, at most half way up to the
// top of its walls (a low object's storey).
double NavigationHeight(const Storey& storey, const FreeSpaceOptions& options);

// One bounded cell of a section, with its kind.
struct SectionCell {
  Ring2 ring;  // counter-clockwise boundary walk of the arrangement (dangling walls as spikes)
  double area = 0.0;
  int component = -1;  // connected component of the walls bounding it
  Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = Eigen::Vector2d::Zero();  // bounding box
  // A point of a free cell at least min_free_half_width from its boundary (its holes too).
  Eigen::Vector2d wide_point = Eigen::Vector2d::Zero();
  SpaceKind kind = SpaceKind::kFree;
  SolidReason solid_reason = SolidReason::kNone;
};

// The walls of a model cut by the horizontal plane at height z: the spans of the vertical faces
// at z, their planar arrangement, and its bounded cells classified. Nesting decides first: a cell
// not inside another component's cell is free, one inside a free cell solid, one inside a solid
// free; then a free cell is solid when it cannot hold a disk of min_free_half_width, or when a
// horizontal face lower than max_obstacle_top above the floor covers it (a box's top).
class PlanSection {
 public:
  static PlanSection Build(const WireframeModel& model, double z,
                           const FreeSpaceOptions& options = {});

  double z() const { return z_; }
  // The wall spans at z (floor plan, metres).
  const std::vector<Segment2>& walls() const { return walls_; }
  const PlanArrangement& arrangement() const { return arrangement_; }
  // Cells by increasing area.
  const std::vector<SectionCell>& cells() const { return cells_; }
  // The smallest cell containing p (-1: none, outside the walls).
  int CellAt(const Eigen::Vector2d& p) const;
  SpaceAt Classify(const Eigen::Vector2d& p) const;
  // The cell around a component of the arrangement (-1: none, the component faces the outside).
  int EnclosingCell(int component) const { return enclosing_of_component_[component]; }
  // Outer rings (counter-clockwise, spikes and straight vertices removed) of the components
  // nested directly inside cell `cell` (pillars, free-standing boxes in a room).
  std::vector<Ring2> NestedFootprints(int cell) const;

 private:
  void ClassifyCells(const WireframeModel& model, const FreeSpaceOptions& options);

  double z_ = 0.0;
  std::vector<Segment2> walls_;
  PlanArrangement arrangement_;
  std::vector<SectionCell> cells_;
  std::vector<int> enclosing_of_component_;  // per component: the cell around it, -1 outside
  std::vector<Ring2> component_outline_;     // per component: its outer boundary (ccw)
};

// Classifies points of space (x, y, z) through plan sections built on demand, one per band
// between the heights of the vertical faces' corners, cut at its middle (walls with vertical and
// horizontal sides have the same section all through the band). A point between two storeys (above
// the walls of one, below the floor of the next) is the slab: solid above the building's cells,
// outside elsewhere.
class FreeSpace {
 public:
  // Uses the model's storeys().
  explicit FreeSpace(const WireframeModel& model, const FreeSpaceOptions& options = {});
  ~FreeSpace();

  SpaceAt Classify(const Eigen::Vector3d& p);
  const PlanSection& SectionAt(double z);
  const FreeSpaceOptions& options() const { return options_; }

 private:
  const WireframeModel& model_;
  FreeSpaceOptions options_;
  std::vector<double> events_;  // heights of the vertical faces' corners, sorted, distinct
  std::map<long, std::unique_ptr<PlanSection>> sections_;  // by band between events
};

// A point inside `ring`, outside `holes` and at least `radius` from all their sides: samples on
// scan lines a quarter of the radius apart (coarser in a large bounding box: about 4096 samples
// over it; no finer than 1 cm). False when no sample is that far: the ring is too narrow.
bool FindWidePoint(const Ring2& ring, const std::vector<Ring2>& holes, double radius,
                   Eigen::Vector2d* point);

}  // namespace linetrack
