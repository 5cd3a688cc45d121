// Visibility in the floor plan, for the view-invariant regions: which faces occlude whatever the
// camera height, conservative "hidden from every point of a region" tests, and the bearings under
// which a region sees an edge. Regions are convex rings; an edge's footprint is its projection on
// the floor plane, one point (vertical edge) or two.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "models/convex_polygon.h"
#include "models/geometry.h"
#include "models/wireframe.h"

namespace linetrack {

// Floor-plan segments of the parts of the vertical faces that cover the model's whole height
// [z_min + tolerance, max(z_max, camera_top) - tolerance] (world z, metres): a sight line between
// two points inside that height range whose plan crosses such a segment hits the face. A face
// with a door cut out occludes on both sides of the door only. Collinear touching pieces merge.
std::vector<Segment2> FullHeightOccluders(const WireframeModel& model, double tolerance,
                                          double camera_top);

// Floor-plan segments of the parts of the vertical faces that cover [z_lo, z_hi] (one storey's
// band of camera heights), collinear touching pieces merged.
std::vector<Segment2> OccludersInBand(const WireframeModel& model, double z_lo, double z_hi);

// A vertical face in its own plane: s metres along `along` from `origin` (floor plan), z up;
// `along` is the plan normal turned a quarter left.
struct WallInPlane {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero(), along = Eigen::Vector2d::UnitX();
  Ring2 s_z;  // the face's corners as (s, z)
  double z_lo = 0.0, z_hi = 0.0;
  Eigen::Vector2d At(double s) const { return origin + s * along; }
};
// The (s, z) polygon of a vertical, non-degenerate face.
WallInPlane ToWallPlane(const ModelFace& face);

// Intervals of s where the polygon `s_z` (points (s, z)) covers the whole band [z_lo, z_hi].
std::vector<std::pair<double, double>> FullHeightSpans(const Ring2& s_z, double z_lo, double z_hi);

// Merges collinear segments that overlap or touch (within `tolerance` metres) into maximal ones.
std::vector<Segment2> MergeCollinear(const std::vector<Segment2>& segments, double tolerance);

// True when the wall blocks every sight line from the region to the footprint: the region on one
// side of the wall's line (touching it allowed), the footprint at least `margin` metres on the
// other side, and the chord of their convex hull along the line inside the wall.
bool HiddenByWall(const Ring2& region, const Ring2& footprint, const Segment2& wall, double margin);
// The same, given the wall's Line2::Through(wall.a, wall.b).
bool HiddenByWall(const Ring2& region, const Ring2& footprint, const Segment2& wall,
                  const Line2& line, double margin);

// Where one wall meets another at an end: the corner and the far ends of this wall and of the
// other.
struct WallCorner {
  Eigen::Vector2d corner = Eigen::Vector2d::Zero();
  Eigen::Vector2d far_self = Eigen::Vector2d::Zero(), far_other = Eigen::Vector2d::Zero();
};
// Per wall of `walls`, the corners it makes with the others: ends within `tolerance` metres, the
// walls not collinear.
std::vector<std::vector<WallCorner>> WallCorners(const std::vector<Segment2>& walls,
                                                 double tolerance);

// True when two walls meeting at `corner`, one from `far_a` and one from `far_b`, block together
// every sight line from the region to the footprint: the corner convex seen from the region
// (each wall's far end on the region's side of the other's line), the footprint at least `margin`
// metres beyond both lines, and both chords of conv(region + footprint) on the walls or on their
// continuations past the corner. Then a sight line meets one wall or the other, where neither
// alone hides the footprint (a room's corner, seen past from inside).
bool HiddenByCorner(const Ring2& region, const Ring2& footprint, const Eigen::Vector2d& corner,
                    const Eigen::Vector2d& far_a, const Eigen::Vector2d& far_b, double margin);

// True when every sight line from the region to the footprint passes through the interior of the
// convex `solid` (a closed loop of occluding walls), robustly: for every direction n,
// max over the region or over the footprint of n.x stays `margin` metres below max over the
// solid (no line separates the solid from a point of each). False when the region overlaps it.
bool HiddenBySolid(const Ring2& region, const Ring2& footprint, const Ring2& solid, double margin);
// The same, given the region's RingCentroid.
bool HiddenBySolid(const Ring2& region, const Eigen::Vector2d& region_centroid,
                   const Ring2& footprint, const Ring2& solid, double margin);

// The part of the floor-plan `footprint` that a camera anywhere in the disk (centre, radius) can
// see under a bearing within [heading - half, heading + half] (radians): the footprint clipped to
// the two half-planes that the disk sweeps along the arc's end directions (when 2 half < pi; the
// whole footprint otherwise). False when nothing is left.
bool ClipToBearingWedge(const Segment2& footprint, const Eigen::Vector2d& centre, double radius,
                        double heading, double half, Segment2* part);

// A counter-clockwise regular polygon of `sides` (>= 3) vertices that holds the disk.
Ring2 PolygonAroundDisk(const Eigen::Vector2d& centre, double radius, int sides);

// World bearings of q - p for p in the region and q in the footprint, as diamond angles
// (DiamondAngle, models/geometry.h): [min, max] with min in [0, 4), max - min < 2 (a half turn);
// `all` when the footprint meets the region.
struct BearingRange {
  double min = 0.0;
  double max = 0.0;
  bool all = false;
};
BearingRange BearingsToFootprint(const Ring2& region, const Ring2& footprint);
// The same, given the region's bounding box [region_lo, region_hi].
BearingRange BearingsToFootprint(const Ring2& region, const Eigen::Vector2d& region_lo,
                                 const Eigen::Vector2d& region_hi, const Ring2& footprint);

}  // namespace linetrack
