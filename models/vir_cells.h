// Internal to the view-invariant regions (models/view_invariant_regions.cc): the convex cells of
// a storey's navigable area, the event rays that refine them, and the solids among the occluders.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "models/convex_polygon.h"
#include "models/navigable_area.h"
#include "models/segment_grid.h"

namespace linetrack {

// A convex cell, its bounding box, and the initial cell it was split from.
struct Cell {
  Ring2 ring;
  Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = Eigen::Vector2d::Zero();
  int parent = -1;
};

Cell MakeCell(Ring2 ring, int parent);

// Splits every cell that `segment` crosses by the segment's line, but no cell whose bounding box
// is already under `min_cell_size` metres on both sides (0: every cell).
void SplitCells(const Segment2& segment, std::vector<Cell>* cells, double min_cell_size = 0.0);

// The parts' bounding box cut by the lines of their boundary edges and of the occluders, each
// drawn only as far as it reaches before meeting a wall of `stoppers` (the occluders and the
// boundaries), and by a grid of `grid_pitch` metres (0: none); the cells inside a part are kept,
// each its own parent.
std::vector<Cell> InitialCells(const std::vector<const AreaPart*>& parts,
                               const SegmentGrid& stoppers, double grid_pitch);

// Which event rays are cast: from points within `range` metres of the occluding vertex, and of
// the rays from one vertex only those at least `min_separation` radians apart (fewer rays leave
// coarser regions, whose lists stay conservative).
struct EventRayOptions {
  double range = 15.0;
  double min_separation = 0.0;
};

// Event rays (Simsarian et al. 1996): from a vertex c of a solid (`solids`) or a free end of a
// wall, away from a point v of `points` that c can start to hide (v sees c, and the walls at c lie
// on one side of the line v-c), up to the next occluder or the box [lo, hi].
std::vector<Segment2> EventRays(const std::vector<Eigen::Vector2d>& points,
                                const SegmentGrid& occluders, const std::vector<Ring2>& solids,
                                const Eigen::AlignedBox2d& box, const EventRayOptions& options);

// Convex pieces of the closed loops of occluders with at most `max_sides` sides that contain no
// cell's centroid (pillars, boxes; the inside of long thick walls is left to the walls).
std::vector<Ring2> Solids(const std::vector<Segment2>& occluders, const std::vector<Cell>& cells,
                          int max_sides);

}  // namespace linetrack
