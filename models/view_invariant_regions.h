// View-invariant regions (Simsarian, Olson, Nandhakumar 1996; Ait Aider et al. 2005, section 2):
// the navigable area cut by the lines through occluding vertices; each region keeps the edges
// visible from it and, per edge, the range of bearings from which it is seen. Used to reduce the
// matcher's correspondence space to the edges possibly visible from a prior.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "models/camera.h"
#include "models/convex_polygon.h"
#include "models/navigable_area.h"
#include "models/plan_visibility.h"
#include "models/segment_grid.h"
#include "models/wireframe.h"

namespace linetrack {

// One model edge in a region's visibility list. Bearings are world angles (counter-clockwise from
// +x) of the directions from points of the region to points of the edge, projected on the floor
// plane, held as diamond angles (DiamondAngle, models/geometry.h: monotone in the bearing, no
// transcendental function): the arc [diamond_min, diamond_max] (diamond_min in [0, 4),
// diamond_max - diamond_min < 2, a half turn) unless all_bearings (the edge passes over the
// region).
struct RegionEdge {
  int edge_id = -1;
  bool all_bearings = false;
  double diamond_min = 0.0;
  double diamond_max = 0.0;
};

// A convex cell of the navigable area on one storey and its visibility list (sorted by edge id).
struct ViewRegion {
  Polygon2 polygon;
  int storey = 0;
  std::vector<RegionEdge> visible;
};

// "Which edges can a camera see from anywhere in this disk, for any heading in this interval?"
struct VisibilityQuery {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  // prior position (metres)
  double radius = 0.0;                               // delta_t (metres)
  double heading = 0.0;                              // prior heading (radians)
  double heading_margin = 0.0;                       // delta_phi (radians)
  // Largest angle (radians) between the heading and the floor-plane bearing of anything in the
  // image; see BearingHalfWidth().
  double bearing_half_width = 0.0;
  // World height of the camera (metres): only the regions of its storey answer; NaN: every
  // storey's.
  double camera_z = std::numeric_limits<double>::quiet_NaN();
};

struct ViewInvariantRegionsOptions {
  // Only faces spanning a storey's whole height (floor to the top of its walls) occlude in the
  // plan; lower faces are conservatively treated as transparent. Tolerance on that test (metres).
  double full_height_tolerance = 0.01;
  // Highest camera position the lists must hold for (world z, metres): a face occludes only when
  // it also reaches above it. The default 0 is below the top of a storey standing on z >= 0, so
  // the storey's top is used; raise it for cameras above low models.
  double camera_top = 0.0;
  // Regions are also cut by a square grid of this pitch (metres; 0: no grid), which bounds their
  // size and so the width of their bearing ranges (the query's own disk test mostly does that).
  double grid_pitch = 0.0;
  // Cut by the event rays (from an occluding vertex away from each model vertex it can hide, up
  // to the next wall; Simsarian et al.), not only by the lines of walls and area boundaries.
  bool event_rays = true;
  // Of the event rays from one occluding vertex, only those at least this far apart (degrees):
  // each door jamb sees hundreds of model vertices, and their rays crossing in a corridor cut it
  // into cells quadratic in number. Fewer rays leave coarser regions, whose lists stay
  // conservative.
  double event_ray_separation_deg = 5.0;
  // Event rays split no region already under this size (metres) on both sides of its bounding
  // box: the matcher queries disks of the prior's position uncertainty, larger than this.
  double min_region_size = 0.5;
  // An edge counts as hidden only when the occluders block every sight line to it by at least
  // this much (metres); keeps the lists conservative against rounding and grazing sight lines.
  double hidden_margin = 1e-3;
  // Test every region against every edge of its storey, walking each sight line through the
  // walls, instead of only the edges its cell sees against the occluders that can hide each from
  // a part of the cell: slow; the reference the tests hold the lists to.
  bool direct_lists = false;
  // Threads computing the regions' visibility lists (0: one per hardware thread). The lists do
  // not depend on it.
  int threads = 0;

  bool Check(std::string* why) const;
};

class ViewInvariantRegions {
 public:
  // Regions of `area` and their visibility lists for `model`, storey by storey
  // (docs/models.md); throws InputError naming the model when the options are invalid.
  static ViewInvariantRegions Build(const WireframeModel& model, const NavigableArea& area,
                                    const ViewInvariantRegionsOptions& options = {});

  const std::vector<ViewRegion>& regions() const { return regions_; }
  int size() const { return static_cast<int>(regions_.size()); }
  // Floor-plan segments of the full-height faces, the occluders the lists were built with (every
  // storey's).
  const std::vector<Segment2>& occluders() const { return occluders_; }
  // Convex pieces of the closed loops of occluders no camera can be inside (pillars, boxes).
  const std::vector<Polygon2>& solids() const { return solids_; }

  // Edges possibly visible from the query (sorted ids, each once): the union of the visibility
  // lists of the regions of the camera's storey meeting the disk, keeping an edge when its bearing
  // range meets [heading - margin - half_width, heading + margin + half_width], and so do the
  // bearings from the disk itself to the edge, and the storey's walls do not hide from the disk
  // the part of the edge under those bearings. Conservative: an edge that ray casting finds visible
  // from a pose inside the query (position in the navigable area, camera height between the model's
  // floor and top) is never missing. Throws InputError on a non-finite or negative field.
  std::vector<int> Query(const VisibilityQuery& query) const;

  // Why Query(query) is empty, for a localisation's reason: the disk meets no region of the
  // camera's storey (it lies outside the navigable area), or the regions it meets see no edge
  // under the query's bearings.
  std::string ExplainEmptyQuery(const VisibilityQuery& query) const;

 private:
  // Fills the grid below from the regions' bounding boxes.
  void BuildGrid(const NavigableArea& area);
  // Adds the regions of storey s.
  void BuildStorey(const WireframeModel& model, const NavigableArea& area, int s,
                   const ViewInvariantRegionsOptions& options);

  // The convex hull of the parts of the regions `met` (indices, of the camera's storey) inside
  // the query's disk (its circumscribed octagon): it holds every position of the query.
  Ring2 EyesInDisk(const VisibilityQuery& query, const std::vector<int>& met) const;
  // True when, seen from anywhere in `eyes` (EyesInDisk), the storey's walls hide every point of
  // the edge's footprint under the query's bearings (half: the bearings' half-width, radians).
  bool HiddenFromDisk(const VisibilityQuery& query, double half, int storey, int edge_id,
                      const Ring2& eyes) const;

  // Per storey, its occluding walls (with their lines and, per wall, the corners it makes with
  // others) and per model edge whether they can hide it (an edge within the storey's band of
  // camera heights).
  struct StoreyWalls {
    SegmentGrid grid = SegmentGrid({});
    std::vector<Line2> lines;
    std::vector<std::vector<WallCorner>> corners;
    std::vector<char> hideable;
  };

  std::vector<ViewRegion> regions_;
  std::vector<StoreyWalls> storey_walls_;
  double hidden_margin_ = 1e-3;  // ViewInvariantRegionsOptions::hidden_margin
  std::vector<Storey> storeys_;
  std::vector<Segment2> occluders_;
  std::vector<Polygon2> solids_;
  int num_edges_ = 0;
  // Floor-plan footprint of each edge (a == b for a vertical edge), for the disk's own bearings.
  std::vector<Segment2> footprints_;
  // A uniform grid over the area's bounds listing the regions meeting each cell.
  Eigen::Vector2d grid_origin_ = Eigen::Vector2d::Zero();
  double grid_cell_ = 1.0;
  int grid_cols_ = 0, grid_rows_ = 0;
  std::vector<std::vector<int>> grid_;
};

// Largest |bearing - heading| (radians) of a floor-plane bearing seen anywhere in an image of
// `camera` at any tilt in [tilt_min, tilt_max] (radians, within +-pi/2); pi when the image may
// contain the nadir or zenith. In the level frame a ray m has bearing offset atan2(mL_x, mL_z).
// The image is the pixel rectangle [0, width - 1] x [0, height - 1] (distorted when the camera
// has distortion), of a camera rolled by `roll` about its optical axis (RobotPose's roll).
// Throws InputError when the camera, the tilt interval or the roll is invalid.
double BearingHalfWidth(const CameraIntrinsics& camera, double tilt_min, double tilt_max,
                        double roll = 0.0);

}  // namespace linetrack
