// Small plane-geometry helpers on vertex rings (floor plane, metres): oriented lines, cutting a
// convex polygon by a line, clipping a segment to it, distances, and the decomposition of a simple
// polygon into convex pieces. Rings are counter-clockwise and not closed (last != first).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "models/geometry.h"

namespace linetrack {

using Ring2 = std::vector<Eigen::Vector2d>;

// The oriented line normal . x = offset (normal unit); positive side = where the normal points.
struct Line2 {
  Eigen::Vector2d normal = Eigen::Vector2d::UnitY();
  double offset = 0.0;

  // The line through a and b (a != b), positive side on the left of a -> b.
  static Line2 Through(const Eigen::Vector2d& a, const Eigen::Vector2d& b);
  double SignedDistance(const Eigen::Vector2d& p) const { return normal.dot(p) - offset; }
  // Unit direction along the line (the normal turned clockwise): a -> b for Through(a, b).
  Eigen::Vector2d Direction() const { return {normal.y(), -normal.x()}; }
};

// Shoelace area (> 0 counter-clockwise) and area centroid of a ring.
double RingSignedArea(const Ring2& ring);
Eigen::Vector2d RingCentroid(const Ring2& ring);

// Crossing-number test of p against any simple ring.
bool RingContains(const Ring2& ring, const Eigen::Vector2d& p);

// True when the interiors of two convex rings are disjoint (touching allowed within `tolerance`
// metres): some edge normal of either separates them (separating axis test).
bool ConvexInteriorsDisjoint(const Ring2& a, const Ring2& b, double tolerance);

// Distance from p to the closed segment s.
double DistanceToSegment(const Eigen::Vector2d& p, const Segment2& s);

// True when p lies in the convex ring or within `tolerance` metres outside it.
bool ConvexContains(const Ring2& convex, const Eigen::Vector2d& p, double tolerance = 0.0);

// Distance from p to the convex ring (0 inside).
double DistanceToConvex(const Ring2& convex, const Eigen::Vector2d& p);

// Cuts a convex ring by `line` into the parts on its positive and negative sides. False (outputs
// untouched) when one part would have an area below `min_area` m^2 (the line misses the ring or
// only grazes it).
bool SplitConvex(const Ring2& convex, const Line2& line, double min_area, Ring2* positive,
                 Ring2* negative);

// Parameters [t0, t1] (0..1 along s) of the part of segment s inside the convex ring; false when
// the segment misses it.
bool ClipSegmentToConvex(const Ring2& convex, const Segment2& s, double* t0, double* t1);

// Lexicographic order of plan points (x, then y): the hull's sweep order, and a canonical order
// for comparing point sets.
inline bool LexicographicLess(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() != b.x() ? a.x() < b.x() : a.y() < b.y();
}

// Counter-clockwise convex hull of `points` (Andrew's monotone chain; sorts them) into `hull`,
// whose storage is reused. Collinear points are left out; one point for coincident points.
void ConvexHull(Ring2* points, Ring2* hull);

// The part of the convex ring on the positive side of `line` (SignedDistance >= 0); empty when
// none of it is.
Ring2 ClipConvex(const Ring2& convex, const Line2& line);

// True when the ring is convex (every turn left, collinear vertices allowed within `tolerance`).
bool IsConvexRing(const Ring2& ring, double tolerance = 1e-12);

// Convex pieces covering a simple counter-clockwise ring exactly: ear-clipping triangulation, then
// Hertel-Mehlhorn merging of neighbouring pieces while the union stays convex. Empty when the
// ring is not simple enough to triangulate.
std::vector<Ring2> ConvexPieces(const Ring2& ring);

// Removes vertices where the ring goes straight on, and spikes (a -> b -> a, both consecutive
// edges on one line, reversed), within `tolerance` metres.
Ring2 SimplifyRing(const Ring2& ring, double tolerance);

}  // namespace linetrack
