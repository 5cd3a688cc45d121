// The set of robot poses consistent with the correspondences assigned so far in the
// interpretation tree. For a fixed heading every correspondence confines the camera position to
// a band (non-vertical edge: the position line; vertical edge: the ray from its foot), so the set
// is kept as heading bins, each with a convex polygon of positions. Each correspondence cuts every
// bin; a bin whose polygon empties is dropped; no bin left prunes the branch. This keeps the
// coupling between heading and position that a single heading interval would lose (two vertical
// correspondences fix the pose up to the inscribed-angle arc: here, a thin polygon per bin).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "matching/constraints.h"
#include "models/robot_pose.h"

namespace linetrack {

// Convex polygon in the floor plane (counter-clockwise), stored inline (no allocation: the
// tree copies and cuts thousands of them per localisation).
class ConvexPolygon {
 public:
  static constexpr int kMaxVertices = 32;

  ConvexPolygon() = default;
  // Regular polygon circumscribing the disk (contains it).
  static ConvexPolygon AroundDisk(const Eigen::Vector2d& centre, double radius, int sides = 12);

  // Keeps the part where n . p + d >= 0.
  void ClipHalfPlane(const Eigen::Vector2d& n, double d);
  // Sets this polygon to the part of `source` where n . p + d >= 0.
  void ClipFrom(const ConvexPolygon& source, const Eigen::Vector2d& n, double d);
  // The same with two half-planes (a band or a wedge).
  void ClipFrom(const ConvexPolygon& source, const Eigen::Vector2d& n1, double d1,
                const Eigen::Vector2d& n2, double d2);
  // True when the part of this polygon where n1 . p + d1 >= 0 and n2 . p + d2 >= 0 is not
  // Empty(): the same answer as ClipFrom with two half-planes, without building it all.
  bool MeetsBoth(const Eigen::Vector2d& n1, double d1, const Eigen::Vector2d& n2, double d2) const;
  bool Empty() const { return count_ < 3; }
  Eigen::Vector2d Centroid() const;  // mean of the vertices
  int size() const { return count_; }
  const Eigen::Vector2d* begin() const { return vertices_.data(); }
  const Eigen::Vector2d* end() const { return vertices_.data() + count_; }
  // Bounding box of the vertices (exactly their least and greatest coordinates; empty: +inf, -inf).
  const Eigen::Vector2d& box_lo() const { return lo_; }
  const Eigen::Vector2d& box_hi() const { return hi_; }
  // Largest n . p + d over the bounding box, plus a rounding margin: when negative, n . v + d is
  // negative for every vertex v as computed (a cheap rejection that cannot change a decision).
  double MaxSideBound(const Eigen::Vector2d& n, double d) const {
    const double x = n.x() > 0.0 ? hi_.x() : lo_.x(), y = n.y() > 0.0 ? hi_.y() : lo_.y();
    const double scale = std::abs(n.x() * x) + std::abs(n.y() * y) + std::abs(d);
    return n.x() * x + n.y() * y + d + 1e-9 * (1.0 + scale);
  }

 private:
  void Push(const Eigen::Vector2d& v) {
    if (count_ == kMaxVertices) {
      PushFull(v);
      return;
    }
    lo_ = lo_.cwiseMin(v);
    hi_ = hi_.cwiseMax(v);
    vertices_[count_++] = v;
  }
  void Clear() {
    count_ = 0;
    lo_.setConstant(std::numeric_limits<double>::infinity());
    hi_ = -lo_;
  }
  void PushFull(const Eigen::Vector2d& v);
  // ClipFrom with side[i] = n . source[i] + d given.
  void ClipFromSides(const ConvexPolygon& source, const double* side);
  std::array<Eigen::Vector2d, kMaxVertices> vertices_;
  int count_ = 0;
  // Bounding box of the vertices, kept by Push and Clear.
  Eigen::Vector2d lo_ = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi_ = Eigen::Vector2d::Constant(-std::numeric_limits<double>::infinity());
};

// Positions possible for headings in [lo, hi]; (cos, sin) of lo, mid and hi cached.
struct HeadingBin {
  // User-provided, so appending a bin to a vector does not zero the polygon's unused vertices
  // (value-initialisation of an aggregate would: about 600 bytes per bin of every cut).
  HeadingBin() {}
  HeadingBin(double lo, double hi, const Eigen::Vector2d& trig_lo, const Eigen::Vector2d& trig_mid,
             const Eigen::Vector2d& trig_hi, const ConvexPolygon& positions)
      : lo(lo),
        hi(hi),
        trig_lo(trig_lo),
        trig_mid(trig_mid),
        trig_hi(trig_hi),
        positions(positions) {}
  double lo = 0.0, hi = 0.0;
  Eigen::Vector2d trig_lo, trig_mid, trig_hi;
  ConvexPolygon positions;
};

struct FeasibleRegion {
  std::vector<HeadingBin> bins;  // ordered by heading, non-empty polygons
  // Bounding box of the positions of all bins (UpdateBox; kept by FromPrior and the cuts).
  Eigen::Vector2d box_lo = Eigen::Vector2d::Zero(), box_hi = Eigen::Vector2d::Zero();
  void UpdateBox();

  // Bins of at most `bin_width` radians covering `heading`, each with the polygon around the disk.
  static FeasibleRegion FromPrior(const HeadingInterval& heading, const Eigen::Vector2d& centre,
                                  double radius, double bin_width);

  bool Empty() const { return bins.empty(); }
  // True when some bin holds the pose (its heading, modulo 2 pi, and its position).
  bool Contains(const Pose3Dof& pose) const;
  // True when every bin's headings lie within `heading_margin` of pose.heading and every
  // polygon vertex within `radius` of its position.
  bool Within(const Pose3Dof& pose, double radius, double heading_margin) const;
  // Hull of the surviving headings.
  HeadingInterval Heading() const { return {bins.front().lo, bins.back().hi}; }
  // Representative poses: for each run of contiguous surviving bins, the middle bin's heading
  // and polygon centroid (the runs are the separate pose clusters the correspondences allow).
  std::vector<Pose3Dof> Representatives() const;

  // Splits bins in halves (each keeps its polygon) while there are at most `max_bins / 2` and
  // they are wider than `min_width` radians: coarse bins while the heading is wide, fine ones
  // once the correspondences have narrowed it.
  void Refine(int max_bins, double min_width);
};

// Cuts `region` with a non-vertical correspondence: bins outside the direction intervals are
// dropped, the others clipped to the position-line band at their mid heading, widened by how far
// the line moves within the bin. Returns false when nothing is left.
bool AddNonVertical(const ObservedLine& line, const MatchEdge& edge, double height, double sigmas,
                    FeasibleRegion* region);
// The same, writing the cut of `in` into `out` (no copy of the bins that do not survive).
bool AddNonVertical(const ObservedLine& line, const MatchEdge& edge, double height, double sigmas,
                    const FeasibleRegion& in, FeasibleRegion* out);

// True when the non-vertical correspondence keeps some of `region` (AddNonVertical would not
// empty it), without building the cut.
bool MeetsNonVertical(const ObservedLine& line, const MatchEdge& edge, double height, double sigmas,
                      const FeasibleRegion& region);

// The region's bounding box as seen from a point (a vertical edge's foot): whether the point is
// within its circumscribed disk, else the direction to the box centre and the half-angle the disk
// subtends (radians). The same for every line matched to that edge, so computed once per edge.
struct BoxView {
  bool covers = false;
  double direction = 0.0, spread = 0.0;
};
BoxView ViewBox(const FeasibleRegion& region, const Eigen::Vector2d& from);

// A vertical correspondence as a cut of the region: in a bin of headings [lo, hi] the camera
// lies in the wedge of directions (h - w) + pi from the edge's foot, h in the bin, widened by
// sigmas times the bearing noise. Built once per (line, edge) pair for many cuts.
class VerticalCut {
 public:
  VerticalCut(const ObservedLine& line, const MatchEdge& edge, double sigmas);
  // The wedge in `bin`: n1 . q + d1 >= 0 and n2 . q + d2 >= 0; false when the bin is too wide
  // for a wedge (everything allowed).
  bool In(const HeadingBin& bin, Eigen::Vector2d* n1, double* d1, Eigen::Vector2d* n2,
          double* d2) const {  // inline: called per bin of every forward check
    if (bin.hi - bin.lo + 2.0 * margin_ >= kPi) return false;
    auto rotate = [](const Eigen::Vector2d& x, const Eigen::Vector2d& y) {
      return Eigen::Vector2d(x.x() * y.x() - x.y() * y.y(), x.x() * y.y() + x.y() * y.x());
    };
    const Eigen::Vector2d u1 = rotate(bin.trig_lo, a_), u2 = rotate(bin.trig_hi, b_);
    *n1 = Eigen::Vector2d(-u1.y(), u1.x());
    *n2 = Eigen::Vector2d(u2.y(), -u2.x());
    *d1 = -n1->dot(foot_);
    *d2 = -n2->dot(foot_);
    return true;
  }
  // Quick test: the directions from the foot to the region's bounding box meet those the
  // headings allow (false: the cut empties the region).
  bool MayMeet(const FeasibleRegion& region) const;
  // The same with `view()` returning ViewBox(region, foot()), called only when needed.
  template <typename ViewFn>
  bool MayMeet(const FeasibleRegion& region, ViewFn&& view) const {
    if (region.Empty()) return false;
    const HeadingInterval heading = region.Heading();
    if (heading.Width() + 2.0 * margin_ >= kPi) return true;
    const BoxView box = view();
    if (box.covers) return true;
    const double wanted = heading.Mid() - bearing_ + kPi;
    const double offset = std::abs(WrapAngle(box.direction - wanted));
    return offset <= box.spread + 0.5 * heading.Width() + margin_;
  }
  const Eigen::Vector2d& foot() const { return foot_; }

 private:
  Eigen::Vector2d foot_;
  double bearing_ = 0.0;
  double margin_ = 0.0;
  Eigen::Vector2d a_, b_;  // (cos, sin) of -w -+ margin + pi
};

// Cuts `region` with a vertical correspondence: each bin's polygon is clipped to the wedge of
// rays from the foot for the bin's headings (widened by the bearing noise).
bool AddVertical(const ObservedLine& line, const MatchEdge& edge, double sigmas,
                 FeasibleRegion* region);
bool AddVertical(const ObservedLine& line, const MatchEdge& edge, double sigmas,
                 const FeasibleRegion& in, FeasibleRegion* out);
// True when the vertical correspondence keeps some of `region`, without building the cut.
bool MeetsVertical(const ObservedLine& line, const MatchEdge& edge, double sigmas,
                   const FeasibleRegion& region);
// The same with the cut built beforehand.
bool AddVertical(const VerticalCut& cut, const FeasibleRegion& in, FeasibleRegion* out);
bool MeetsVertical(const VerticalCut& cut, const FeasibleRegion& region);
// The same with ViewBox(region, cut.foot()) given (shared by the cuts of one edge); `view` is
// called only when needed and must return the same view each time.
template <typename ViewFn>
bool MeetsVertical(const VerticalCut& cut, const FeasibleRegion& region, ViewFn&& view) {
  if (region.bins.size() > 4 && !cut.MayMeet(region, view)) return false;
  for (const HeadingBin& bin : region.bins) {
    Eigen::Vector2d n1, n2;
    double d1 = 0.0, d2 = 0.0;
    if (!cut.In(bin, &n1, &d1, &n2, &d2)) return true;
    if (bin.positions.MeetsBoth(n1, d1, n2, d2)) return true;
  }
  return false;
}

}  // namespace linetrack
