// View-invariant regions (Simsarian, Olson, Nandhakumar 1996; Ait Aider et al. 2005, section 2):
// the navigable area cut by the lines through occluding vertices; each region keeps the edges
// visible from it and, per edge, the range of bearings from which it is seen. Used to reduce the
// matcher's correspondence space to the edges possibly visible from a prior.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/wireframe.h"

namespace linetrack {

// One model edge in a region's visibility list. Bearings are world angles (radians,
// counter-clockwise from +x) of the directions from points of the region to points of the edge,
// projected on the floor plane: the interval [bearing_min, bearing_max] (bearing_max may exceed
// pi; width < 2 pi) unless all_bearings (the edge passes over the region).
struct RegionEdge {
  int edge_id = -1;
  double bearing_min = 0.0;
  double bearing_max = 0.0;
  bool all_bearings = false;
};

// A convex cell of the navigable area and its visibility list (sorted by edge id).
struct ViewRegion {
  Polygon2 polygon;
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
};

struct ViewInvariantRegionsOptions {
  // Only faces spanning the model's whole height (floor to ceiling) occlude in the plan; lower
  // faces are conservatively treated as transparent. Tolerance on that test (metres).
  double full_height_tolerance = 0.01;

  bool Check(std::string* why) const;
};

class ViewInvariantRegions {
 public:
  static ViewInvariantRegions Build(const WireframeModel& model, const NavigableArea& area,
                                    const ViewInvariantRegionsOptions& options = {});

  const std::vector<ViewRegion>& regions() const { return regions_; }
  int size() const { return static_cast<int>(regions_.size()); }

  // Edges possibly visible from the query (sorted ids, each once): the union of the visibility
  // lists of the regions meeting the disk, keeping an edge when its bearing range meets
  // [heading - margin - half_width, heading + margin + half_width]. Conservative: an edge that
  // ray casting finds visible from a pose inside the query is never missing.
  std::vector<int> Query(const VisibilityQuery& query) const;

 private:
  std::vector<ViewRegion> regions_;
  // A uniform grid over the area's bounds listing the regions meeting each cell.
  Eigen::Vector2d grid_origin_ = Eigen::Vector2d::Zero();
  double grid_cell_ = 1.0;
  int grid_cols_ = 0, grid_rows_ = 0;
  std::vector<std::vector<int>> grid_;
};

// Largest |bearing - heading| (radians) of a floor-plane bearing seen anywhere in an image of
// `camera` at any tilt in [tilt_min, tilt_max] (radians); pi when the image may contain the nadir
// or zenith. In the level frame a ray m has bearing offset atan2(mL_x, mL_z).
double BearingHalfWidth(const CameraIntrinsics& camera, double tilt_min, double tilt_max);

}  // namespace linetrack
