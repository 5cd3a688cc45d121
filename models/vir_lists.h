// Internal to the view-invariant regions (models/view_invariant_regions.cc): the visibility lists
// of a storey's cells and of the regions split from them. A region sees no more than its cell, and
// only the occluders that meet the hull of the cell and an edge's footprint can hide the edge from
// a part of the cell: a region tests those alone, and gets the list a walk along every sight line
// would give.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "models/convex_polygon.h"
#include "models/segment_grid.h"
#include "models/view_invariant_regions.h"
#include "models/vir_cells.h"
#include "models/wireframe.h"

namespace linetrack {

// The edges one storey's regions list: those within its height band can be hidden by its
// occluders; those outside it (seen over the walls) are listed in every region.
struct StoreyEdges {
  std::vector<int> ids;
  std::vector<Ring2> footprints;  // per entry of ids
  std::vector<char> in_band;      // per entry of ids
  // Per entry of ids: the first entry with the same footprint points (in any order) and band,
  // itself when none. The top and bottom edges of a wall share a footprint: whether the occluders
  // hide it, and which can, is decided once per cell and region.
  std::vector<int> same_as;
  double z_lo = 0.0, z_hi = 0.0;  // the cameras' band (metres)
  const std::vector<std::vector<int>>* one_sided_faces =
      nullptr;  // per edge id: its faces, all one-sided
};

// The occluders and solids of one storey, in grids along which sight lines are walked.
struct StoreyOccluders {
  SegmentGrid walls;
  std::vector<double> wall_lengths;  // per wall of `walls` (metres)
  std::vector<Line2> wall_lines;     // per wall: Line2::Through(a, b)
  std::vector<Ring2> solids;
  SegmentGrid solid_sides;             // the solids' sides
  std::vector<int> solid_of_side;      // per side: its solid
  mutable std::vector<unsigned> seen;  // per solid: the last visibility test that met it
  mutable unsigned test = 0;
};

// An occluder that can hide an edge from a part of a cell: a wall (index into the walls' grid) or
// a solid (-1 - index), and a box (rounded outwards) holding every point of the cell it can hide
// the edge from.
struct CellOccluder {
  int id = 0;
  float lo_x = 0.0f, lo_y = 0.0f, hi_x = 0.0f, hi_y = 0.0f;
};

// A cell's visibility list, the candidates of the regions split from it: the edges it sees
// (indices into StoreyEdges::ids, ascending) and, for edge j, occluders[first[j], first[j + 1]):
// the walls with the footprint beyond their line by the hidden margin whose shadow meets the cell,
// and the solids that meet the hull of the cell and the footprint.
// With the occluders, per edge: whether a part of the cell may lie behind all its faces.
struct CellList {
  std::vector<int> edges;
  std::vector<int> first;
  std::vector<CellOccluder> occluders;
  std::vector<char> maybe_behind;
};

// Whether a cell's list keeps, per edge, the occluders that can hide it from a part of the cell:
// worth it for a cell split into many regions; without them a region walks each sight line.
enum class CellOccluders { kKeep, kNone };

// The list of cell `ring` among all the storey's edges: an edge is out of sight behind its
// one-sided faces, or when an occluder or a solid hides its whole footprint from the whole cell
// by `margin` metres (one met by the sight line between their centres: docs/models.md).
CellList CellVisibility(const Ring2& ring, const WireframeModel& model, const StoreyEdges& edges,
                        const StoreyOccluders& occluders, double margin, CellOccluders keep);

// The visibility list (with bearing ranges) of a region (a cell split from the cell of `cell`):
// the same test as CellVisibility's, among the cell's edges, against each edge's occluders when
// the cell kept them, else by walking the sight line between the centres.
std::vector<RegionEdge> RegionVisibility(const Cell& region, const WireframeModel& model,
                                         const StoreyEdges& edges, const CellList& cell,
                                         const StoreyOccluders& occluders, double margin);

// The visibility list of a region tested directly against every edge of the storey, walking the
// sight line between their centres through the walls: the reference RegionVisibility must equal.
std::vector<RegionEdge> DirectVisibility(const Cell& region, const WireframeModel& model,
                                         const StoreyEdges& edges, const StoreyOccluders& occluders,
                                         double margin);

// False only when an axis (an edge normal of the counter-clockwise convex `ring`, or the normal
// of s) separates segment s from the ring by more than `tolerance` metres: never false when s
// comes within `tolerance` of it.
bool SegmentNearConvex(const Ring2& ring, const Segment2& s, double tolerance);

// The part of the convex `ring` that lies, within `slack` metres, in the shadow that `wall`
// (lengthened by `slack` at both ends) casts from every point of `footprint`: on the far side of
// the wall's line, with the segments from it to the footprint all crossing the wall. `line` is
// Line2::Through(wall.a, wall.b), with the footprint at least `margin` metres on one side. False
// when that part is empty, else its box in `lo`, `hi`.
bool ShadowBox(const Ring2& ring, const Ring2& footprint, const Segment2& wall, const Line2& line,
               double slack, Eigen::Vector2d* lo, Eigen::Vector2d* hi);

}  // namespace linetrack
