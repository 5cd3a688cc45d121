#include "matching/feasible_region.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace linetrack {
namespace {

// A position line normalised so |(A, B)| = 1.
Eigen::Vector3d Unit(const Eigen::Vector3d& l) {
  return l / std::sqrt(l.x() * l.x() + l.y() * l.y());
}

double SignedDistance(const Eigen::Vector3d& unit_line, const Eigen::Vector2d& q) {
  return unit_line.x() * q.x() + unit_line.y() * q.y() + unit_line.z();
}

Eigen::Vector2d Trig(double a) {
  return {std::cos(a), std::sin(a)};
}

// Appends a bin with `bin`'s headings to `out`, reusing the storage of a previous bin there.
HeadingBin& Append(const HeadingBin& bin, FeasibleRegion* out) {
  out->bins.emplace_back();
  HeadingBin& b = out->bins.back();
  b.lo = bin.lo;
  b.hi = bin.hi;
  b.trig_lo = bin.trig_lo;
  b.trig_mid = bin.trig_mid;
  b.trig_hi = bin.trig_hi;
  return b;
}

// The half-plane n . v + d >= 0.
struct HalfPlane {
  const Eigen::Vector2d& n;
  double d = 0.0;
};

// How many vertices lie on the kept side of each of two half-planes.
struct InsideCounts {
  int first = 0;
  int second = 0;
};

// side_k[i] = n_k . v[i] + d_k for the m vertices v and both half-planes h_k; returns how many
// vertices are on the kept side (side_k >= 0) of each.
InsideCounts BothSides(const Eigen::Vector2d* v, int m, const HalfPlane& h1, const HalfPlane& h2,
                       double* side1, double* side2) {
  InsideCounts inside;
  for (int i = 0; i < m; ++i) {
    side1[i] = h1.n.dot(v[i]) + h1.d;
    side2[i] = h2.n.dot(v[i]) + h2.d;
    inside.first += side1[i] >= 0.0 ? 1 : 0;
    inside.second += side2[i] >= 0.0 ? 1 : 0;
  }
  return inside;
}

bool Overlaps(const HeadingBin& bin, const HeadingInterval* parts, int count) {
  for (int i = 0; i < count; ++i) {
    if (parts[i].lo <= bin.hi && parts[i].hi >= bin.lo) return true;
  }
  return false;
}

}  // namespace

ConvexPolygon ConvexPolygon::AroundDisk(const Eigen::Vector2d& centre, double radius, int sides) {
  ConvexPolygon polygon;
  sides = std::clamp(sides, 3, kMaxVertices);
  const double r = std::max(radius, 1e-3) / std::cos(kPi / sides);
  for (int i = 0; i < sides; ++i) {
    const double a = 2.0 * kPi * i / sides;
    polygon.Push(centre + r * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  return polygon;
}

void ConvexPolygon::PushFull(const Eigen::Vector2d& v) {
  // Out of room (many cuts that each add a vertex): replace by the bounding box, which
  // contains the polygon, so the region stays conservative.
  Eigen::Vector2d lo = vertices_[0], hi = vertices_[0];
  for (int i = 1; i < count_; ++i) {
    lo = lo.cwiseMin(vertices_[i]);
    hi = hi.cwiseMax(vertices_[i]);
  }
  lo = lo.cwiseMin(v);
  hi = hi.cwiseMax(v);
  vertices_[0] = lo;
  vertices_[1] = {hi.x(), lo.y()};
  vertices_[2] = hi;
  vertices_[3] = {lo.x(), hi.y()};
  count_ = 4;
  lo_ = lo;
  hi_ = hi;
}

void ConvexPolygon::ClipHalfPlane(const Eigen::Vector2d& n, double d) {
  if (count_ == 0) return;
  bool all_inside = true;
  for (int i = 0; i < count_ && all_inside; ++i)
    all_inside = n.dot(vertices_[i]) + d >= 0.0;
  if (all_inside) return;
  const ConvexPolygon source = *this;
  ClipFrom(source, n, d);
}

void ConvexPolygon::ClipFrom(const ConvexPolygon& source, const Eigen::Vector2d& n, double d) {
  std::array<double, kMaxVertices> side;
  for (int i = 0; i < source.count_; ++i)
    side[i] = n.dot(source.vertices_[i]) + d;
  ClipFromSides(source, side.data());
}

void ConvexPolygon::ClipFromSides(const ConvexPolygon& source, const double* side) {
  Clear();
  const int m = source.count_;
  for (int i = 0; i < m; ++i) {
    const int k = i + 1 == m ? 0 : i + 1;
    const Eigen::Vector2d& a = source.vertices_[i];
    const double fa = side[i], fb = side[k];
    if (fa >= 0.0) Push(a);
    if ((fa >= 0.0) != (fb >= 0.0)) Push(a + (fa / (fa - fb)) * (source.vertices_[k] - a));
  }
}

void ConvexPolygon::ClipFrom(const ConvexPolygon& source, const Eigen::Vector2d& n1, double d1,
                             const Eigen::Vector2d& n2, double d2) {
  // Most cuts keep a polygon whole or drop it: decide those from the box, then from the
  // vertices' sides.
  if (source.count_ == 0 || source.MaxSideBound(n1, d1) < 0.0 ||
      source.MaxSideBound(n2, d2) < 0.0) {
    Clear();
    return;
  }
  std::array<double, kMaxVertices> side1, side2;
  const InsideCounts inside =
      BothSides(source.begin(), source.count_, {n1, d1}, {n2, d2}, side1.data(), side2.data());
  const int inside1 = inside.first, inside2 = inside.second;
  const bool all1 = inside1 == source.count_, all2 = inside2 == source.count_;
  if (inside1 == 0 || inside2 == 0) {
    Clear();
  } else if (all1 && all2) {
    std::copy(source.begin(), source.end(), vertices_.begin());
    count_ = source.count_;
    lo_ = source.lo_;
    hi_ = source.hi_;
  } else if (all1) {
    ClipFromSides(source, side2.data());
  } else if (all2) {
    ClipFromSides(source, side1.data());
  } else {
    ConvexPolygon half;
    half.ClipFromSides(source, side1.data());
    ClipFrom(half, n2, d2);
  }
}

namespace {

// Vertices ClipFromSides would push: those inside and the crossings. The clip is Empty() exactly
// when they are fewer than 3 (a full polygon is replaced by a 4-vertex box, never fewer).
int ClippedCount(int m, const double* side) {
  int count = 0;
  for (int i = 0; i < m; ++i) {
    const double fa = side[i], fb = side[i + 1 == m ? 0 : i + 1];
    count += (fa >= 0.0 ? 1 : 0) + ((fa >= 0.0) != (fb >= 0.0) ? 1 : 0);
  }
  return count;
}

}  // namespace

bool ConvexPolygon::MeetsBoth(const Eigen::Vector2d& n1, double d1, const Eigen::Vector2d& n2,
                              double d2) const {
  if (count_ == 0 || MaxSideBound(n1, d1) < 0.0 || MaxSideBound(n2, d2) < 0.0) return false;
  std::array<double, kMaxVertices> side1, side2;
  const InsideCounts inside =
      BothSides(begin(), count_, {n1, d1}, {n2, d2}, side1.data(), side2.data());
  const bool all1 = inside.first == count_, all2 = inside.second == count_;
  if (inside.first == 0 || inside.second == 0) return false;
  if (all1 && all2) return !Empty();
  if (all1) return ClippedCount(count_, side2.data()) >= 3;
  if (all2) return ClippedCount(count_, side1.data()) >= 3;
  ConvexPolygon half;
  half.ClipFromSides(*this, side1.data());
  for (int i = 0; i < half.count_; ++i)
    side2[i] = n2.dot(half.vertices_[i]) + d2;
  return ClippedCount(half.count_, side2.data()) >= 3;
}

Eigen::Vector2d ConvexPolygon::Centroid() const {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int i = 0; i < count_; ++i)
    sum += vertices_[i];
  return count_ == 0 ? sum : Eigen::Vector2d(sum / static_cast<double>(count_));
}

FeasibleRegion FeasibleRegion::FromPrior(const HeadingInterval& heading,
                                         const Eigen::Vector2d& centre, double radius,
                                         double bin_width) {
  FeasibleRegion region;
  const int count = std::max(1, static_cast<int>(std::ceil(heading.Width() / bin_width)));
  const ConvexPolygon disk = ConvexPolygon::AroundDisk(centre, radius);
  for (int i = 0; i < count; ++i) {
    const double lo = heading.lo + heading.Width() * i / count;
    const double hi = heading.lo + heading.Width() * (i + 1) / count;
    region.bins.push_back({lo, hi, Trig(lo), Trig(0.5 * (lo + hi)), Trig(hi), disk});
  }
  region.UpdateBox();
  return region;
}

void FeasibleRegion::UpdateBox() {
  box_lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  box_hi = -box_lo;
  for (const HeadingBin& bin : bins) {  // the polygons keep their boxes
    box_lo = box_lo.cwiseMin(bin.positions.box_lo());
    box_hi = box_hi.cwiseMax(bin.positions.box_hi());
  }
}

bool FeasibleRegion::Contains(const Pose3Dof& pose) const {
  const Eigen::Vector2d q(pose.x, pose.y);
  for (const HeadingBin& bin : bins) {
    const double h = pose.heading + 2.0 * kPi * std::round((bin.lo - pose.heading) / (2.0 * kPi));
    if (h < bin.lo || h > bin.hi || bin.positions.Empty()) continue;
    bool inside = true;
    const Eigen::Vector2d* v = bin.positions.begin();
    const int n = bin.positions.size();
    for (int i = 0; i < n && inside; ++i)
      inside = Cross2(v[(i + 1) % n] - v[i], q - v[i]) >= 0.0;
    if (inside) return true;
  }
  return false;
}

bool FeasibleRegion::Within(const Pose3Dof& pose, double radius, double heading_margin) const {
  if (bins.empty()) return false;
  // The bins' headings run continuously: bring the pose's heading next to them once.
  const double h =
      pose.heading + 2.0 * kPi * std::round((bins.front().lo - pose.heading) / (2.0 * kPi));
  if (bins.front().lo < h - heading_margin || bins.back().hi > h + heading_margin) return false;
  const double r2 = radius * radius;
  const Eigen::Vector2d q(pose.x, pose.y);
  for (const HeadingBin& bin : bins) {
    for (const Eigen::Vector2d& v : bin.positions) {
      if ((v - q).squaredNorm() > r2) return false;
    }
  }
  return true;
}

void FeasibleRegion::Refine(int max_bins, double min_width) {
  while (!bins.empty() && 2 * static_cast<int>(bins.size()) <= max_bins &&
         bins.front().hi - bins.front().lo > 2.0 * min_width) {
    std::vector<HeadingBin> split;
    split.reserve(2 * bins.size());
    for (const HeadingBin& b : bins) {
      const double mid = 0.5 * (b.lo + b.hi);
      split.push_back({b.lo, mid, b.trig_lo, Trig(0.5 * (b.lo + mid)), Trig(mid), b.positions});
      split.push_back({mid, b.hi, Trig(mid), Trig(0.5 * (mid + b.hi)), b.trig_hi, b.positions});
    }
    bins.swap(split);
  }
}

std::vector<Pose3Dof> FeasibleRegion::Representatives() const {
  std::vector<Pose3Dof> poses;
  size_t first = 0;
  for (size_t i = 1; i <= bins.size(); ++i) {
    const bool run_ends =
        i == bins.size() || bins[i].lo - bins[i - 1].hi > 0.5 * (bins[i].hi - bins[i].lo);
    if (!run_ends) continue;
    const HeadingBin& bin = bins[(first + i - 1) / 2];
    const Eigen::Vector2d c = bin.positions.Centroid();
    poses.push_back({c.x(), c.y(), 0.5 * (bin.lo + bin.hi)});
    first = i;
  }
  return poses;
}

namespace {

// The band of positions a non-vertical correspondence allows in `bin`: |s(q)| <= half_width with
// s the signed distance to the unit position line at the bin's mid heading, widened by how far
// the line moves within the bin (its offset is affine in the position, so the polygon's vertices
// bound the change).
struct Band {
  Eigen::Vector2d normal;
  double offset = 0.0;  // s(q) = normal . q + offset
  double half_width = 0.0;
  double lo = 0.0, hi = 0.0;  // least and greatest s over the polygon's vertices
};

Band NonVerticalBand(const ObservedLine& line, const MatchEdge& edge, double height, double sigmas,
                     const HeadingBin& bin) {
  const Eigen::Vector2d centre = bin.positions.Centroid();
  const Eigen::Vector3d p =
      ObservedPointOnEdge(line, edge, height, bin.trig_mid.x(), bin.trig_mid.y(), centre);
  const PositionLines lines(line.normal, p, height);
  const Eigen::Vector3d mid_line = lines.At(bin.trig_mid.x(), bin.trig_mid.y());
  const Eigen::Vector3d mid = Unit(mid_line);
  const Eigen::Vector3d lo = Unit(lines.At(bin.trig_lo.x(), bin.trig_lo.y()));
  const Eigen::Vector3d hi = Unit(lines.At(bin.trig_hi.x(), bin.trig_hi.y()));
  double slack = 0.0, lo_s = std::numeric_limits<double>::infinity(), hi_s = -lo_s;
  for (const Eigen::Vector2d& q : bin.positions) {
    const double s = SignedDistance(mid, q);
    lo_s = std::min(lo_s, s);
    hi_s = std::max(hi_s, s);
    slack =
        std::max({slack, std::abs(SignedDistance(lo, q) - s), std::abs(SignedDistance(hi, q) - s)});
  }
  return {Eigen::Vector2d(mid.x(), mid.y()), mid.z(),
          PositionBandHalfWidth(line, p, Eigen::Vector3d(centre.x(), centre.y(), height),
                                bin.trig_mid, sigmas, mid_line) +
              slack,
          lo_s, hi_s};
}

}  // namespace

VerticalCut::VerticalCut(const ObservedLine& line, const MatchEdge& edge, double sigmas)
    : foot_(edge.foot),
      bearing_(line.bearing),
      margin_(sigmas * line.bearing_sigma),
      a_(Trig(-line.bearing - margin_ + kPi)),
      b_(Trig(-line.bearing + margin_ + kPi)) {}

BoxView ViewBox(const FeasibleRegion& region, const Eigen::Vector2d& from) {
  BoxView view;
  const Eigen::Vector2d centre = 0.5 * (region.box_lo + region.box_hi);
  const double reach = 0.5 * (region.box_hi - region.box_lo).norm();
  const Eigen::Vector2d to_box = centre - from;
  const double distance = to_box.norm();
  view.covers = distance <= reach;
  if (view.covers) return view;
  view.spread = std::asin(reach / distance);
  view.direction = std::atan2(to_box.y(), to_box.x());
  return view;
}

bool VerticalCut::MayMeet(const FeasibleRegion& in) const {
  return MayMeet(in, [&] { return ViewBox(in, foot_); });
}

bool AddNonVertical(const ObservedLine& line, const MatchEdge& edge, double height, double sigmas,
                    const FeasibleRegion& in, FeasibleRegion* out) {
  out->bins.clear();
  if (in.Empty()) return false;
  HeadingInterval parts[kMaxDirectionIntervals];
  const int count = DirectionIntervals(line, edge.dir, in.Heading(), sigmas, parts);
  for (const HeadingBin& bin : in.bins) {
    if (!Overlaps(bin, parts, count)) continue;
    const Band band = NonVerticalBand(line, edge, height, sigmas, bin);
    // |s(q)| <= half_width: two half-planes of the unit line.
    HeadingBin& cut = Append(bin, out);
    cut.positions.ClipFrom(bin.positions, -band.normal, band.half_width - band.offset, band.normal,
                           band.half_width + band.offset);
    if (cut.positions.Empty()) out->bins.pop_back();
  }
  out->UpdateBox();
  return !out->Empty();
}

bool MeetsNonVertical(const ObservedLine& line, const MatchEdge& edge, double height, double sigmas,
                      const FeasibleRegion& region) {
  if (region.Empty()) return false;
  HeadingInterval parts[kMaxDirectionIntervals];
  const int count = DirectionIntervals(line, edge.dir, region.Heading(), sigmas, parts);
  if (count == 0) return false;
  for (const HeadingBin& bin : region.bins) {
    if (!Overlaps(bin, parts, count)) continue;
    if (bin.positions.Empty()) continue;
    // The band's own pass over the vertices gave the range of s (the bounding-box rejection
    // that stood here cannot change this test's answer).
    const Band band = NonVerticalBand(line, edge, height, sigmas, bin);
    if (band.hi >= -band.half_width && band.lo <= band.half_width) return true;
  }
  return false;
}

bool AddVertical(const VerticalCut& cut, const FeasibleRegion& in, FeasibleRegion* out) {
  out->bins.clear();
  if (!cut.MayMeet(in)) return false;
  for (const HeadingBin& bin : in.bins) {
    HeadingBin& kept = Append(bin, out);
    Eigen::Vector2d n1, n2;
    double d1 = 0.0, d2 = 0.0;
    if (!cut.In(bin, &n1, &d1, &n2, &d2)) {
      kept.positions = bin.positions;
      continue;
    }
    kept.positions.ClipFrom(bin.positions, n1, d1, n2, d2);
    if (kept.positions.Empty()) out->bins.pop_back();
  }
  out->UpdateBox();
  return !out->Empty();
}

bool AddVertical(const ObservedLine& line, const MatchEdge& edge, double sigmas,
                 const FeasibleRegion& in, FeasibleRegion* out) {
  return AddVertical(VerticalCut(line, edge, sigmas), in, out);
}

bool MeetsVertical(const VerticalCut& cut, const FeasibleRegion& region) {
  return MeetsVertical(cut, region, [&] { return ViewBox(region, cut.foot()); });
}

bool MeetsVertical(const ObservedLine& line, const MatchEdge& edge, double sigmas,
                   const FeasibleRegion& region) {
  return MeetsVertical(VerticalCut(line, edge, sigmas), region);
}

bool AddNonVertical(const ObservedLine& line, const MatchEdge& edge, double height, double sigmas,
                    FeasibleRegion* region) {
  const FeasibleRegion in = *region;
  return AddNonVertical(line, edge, height, sigmas, in, region);
}

bool AddVertical(const ObservedLine& line, const MatchEdge& edge, double sigmas,
                 FeasibleRegion* region) {
  const FeasibleRegion in = *region;
  return AddVertical(line, edge, sigmas, in, region);
}

}  // namespace linetrack
