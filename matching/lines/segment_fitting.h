// Pure geometry of image line segments for the line extractors: a segment fitted to pixel
// chains (total least squares), and the merging of collinear fragments.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "models/geometry.h"

namespace linetrack {

// The segment that best fits `points` (pixels): the total-least-squares line through their
// centroid (principal direction of their scatter), cut at the extreme projections of the points.
// Needs at least two distinct points (else a zero-length segment at the centroid).
Segment2 FitSegment(const std::vector<Eigen::Vector2d>& points);

// Root mean square perpendicular distance of `points` from the line through `s` (pixels).
double LineFitRms(const std::vector<Eigen::Vector2d>& points, const Segment2& s);

// When two image segments are fragments of one line.
struct CollinearMergeOptions {
  double max_angle_deg = 2.0;  // between their (undirected) directions
  double max_offset_px = 2.0;  // the shorter one's endpoints from the longer one's line
  double max_gap_px = 12.0;    // between their facing ends along the line (overlap is fine)

  bool Check(std::string* why) const;
};

// Angle between the undirected lines of two segments, in [0, pi/2] radians.
double LineAngle(const Segment2& a, const Segment2& b);

// True when `a` and `b` are fragments of one line: directions within max_angle, the shorter
// one's endpoints within max_offset of the longer one's line, and a gap along the line within
// max_gap.
bool AreCollinearFragments(const Segment2& a, const Segment2& b,
                           const CollinearMergeOptions& options);

// One segment covering both: the line through the length-weighted mean of the midpoints along the
// length-weighted mean direction, cut at the extreme projections of the four endpoints; keeps
// the direction (a to b) of the longer input.
Segment2 MergeSegmentPair(const Segment2& a, const Segment2& b);

// Merges collinear fragments until no pair qualifies, longest segments first (so a long line
// absorbs its fragments before fragments pair among themselves). Order of the result: by length,
// longest first.
std::vector<Segment2> MergeCollinearSegments(std::vector<Segment2> segments,
                                             const CollinearMergeOptions& options);

}  // namespace linetrack
