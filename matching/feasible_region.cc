#include "matching/feasible_region.h"

#include <algorithm>
#include <cmath>

namespace linetrack {
namespace {

// Position line at the heading whose (cos, sin) is `trig`, normalised so |(A, B)| = 1.
Eigen::Vector3d UnitPositionLine(const ObservedLine& line, const Eigen::Vector3d& p, double height,
                                 const Eigen::Vector2d& trig) {
  const Eigen::Vector3d l = PositionLine(line.normal, p, height, trig.x(), trig.y());
  return l / std::sqrt(l.x() * l.x() + l.y() * l.y());
}

double SignedDistance(const Eigen::Vector3d& unit_line, const Eigen::Vector2d& q) {
  return unit_line.x() * q.x() + unit_line.y() * q.y() + unit_line.z();
}

// Keeps the part of `polygon` where |s(q)| <= half_width, s the signed distance to the unit line.
void ClipBand(const Eigen::Vector3d& l, double half_width, ConvexPolygon* polygon) {
  const Eigen::Vector2d n(l.x(), l.y());
  polygon->ClipHalfPlane(-n, half_width - l.z());  // s <= w
  polygon->ClipHalfPlane(n, half_width + l.z());   // s >= -w
}

Eigen::Vector2d Trig(double a) {
  return {std::cos(a), std::sin(a)};
}

bool Overlaps(const HeadingBin& bin, const std::vector<HeadingInterval>& parts) {
  for (const HeadingInterval& p : parts) {
    if (p.lo <= bin.hi && p.hi >= bin.lo) return true;
  }
  return false;
}

void DropEmpty(FeasibleRegion* region) {
  region->bins.erase(std::remove_if(region->bins.begin(), region->bins.end(),
                                    [](const HeadingBin& b) { return b.positions.Empty(); }),
                     region->bins.end());
}

}  // namespace

ConvexPolygon ConvexPolygon::AroundDisk(const Eigen::Vector2d& centre, double radius, int sides) {
  ConvexPolygon polygon;
  const double r = std::max(radius, 1e-3) / std::cos(kPi / sides);
  for (int i = 0; i < sides; ++i) {
    const double a = 2.0 * kPi * i / sides;
    polygon.vertices_.push_back(centre + r * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  return polygon;
}

void ConvexPolygon::ClipHalfPlane(const Eigen::Vector2d& n, double d) {
  if (vertices_.empty()) return;
  bool all_inside = true;
  for (const Eigen::Vector2d& v : vertices_)
    all_inside = all_inside && n.dot(v) + d >= 0.0;
  if (all_inside) return;
  // Built in a reused buffer, swapped in: no allocation once the buffers have grown.
  thread_local std::vector<Eigen::Vector2d> out;
  out.clear();
  for (size_t i = 0; i < vertices_.size(); ++i) {
    const Eigen::Vector2d& a = vertices_[i];
    const Eigen::Vector2d& b = vertices_[(i + 1) % vertices_.size()];
    const double fa = n.dot(a) + d, fb = n.dot(b) + d;
    if (fa >= 0.0) out.push_back(a);
    if ((fa >= 0.0) != (fb >= 0.0)) out.push_back(a + (fa / (fa - fb)) * (b - a));
  }
  vertices_.swap(out);
}

Eigen::Vector2d ConvexPolygon::Centroid() const {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& v : vertices_)
    sum += v;
  return vertices_.empty() ? sum : Eigen::Vector2d(sum / static_cast<double>(vertices_.size()));
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
  return region;
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

Pose3Dof FeasibleRegion::Representative() const {
  const HeadingBin& bin = bins[bins.size() / 2];
  const Eigen::Vector2d c = bin.positions.Centroid();
  return {c.x(), c.y(), 0.5 * (bin.lo + bin.hi)};
}

bool AddNonVertical(const ObservedLine& line, const MatchEdge& edge, double height, double sigmas,
                    FeasibleRegion* region) {
  if (region->Empty()) return false;
  const std::vector<HeadingInterval> parts =
      DirectionIntervals(line, edge.dir, region->Heading(), sigmas);
  for (HeadingBin& bin : region->bins) {
    if (!Overlaps(bin, parts)) {
      bin.positions = ConvexPolygon();
      continue;
    }
    const Eigen::Vector2d centre = bin.positions.Centroid();
    const Eigen::Vector3d p =
        ObservedPointOnEdge(line, edge, height, bin.trig_mid.x(), bin.trig_mid.y(), centre);
    const Eigen::Vector3d mid = UnitPositionLine(line, p, height, bin.trig_mid);
    const Eigen::Vector3d lo = UnitPositionLine(line, p, height, bin.trig_lo);
    const Eigen::Vector3d hi = UnitPositionLine(line, p, height, bin.trig_hi);
    // The line moves within the bin: its offset is affine in the position, so the polygon's
    // vertices bound the change.
    double slack = 0.0;
    for (const Eigen::Vector2d& q : bin.positions.vertices()) {
      const double s = SignedDistance(mid, q);
      slack = std::max(
          {slack, std::abs(SignedDistance(lo, q) - s), std::abs(SignedDistance(hi, q) - s)});
    }
    const double band =
        PositionBandHalfWidth(line, p, height, 0.5 * (bin.lo + bin.hi), centre, sigmas);
    ClipBand(mid, band + slack, &bin.positions);
  }
  DropEmpty(region);
  return !region->Empty();
}

bool AddVertical(const ObservedLine& line, const MatchEdge& edge, double sigmas,
                 FeasibleRegion* region) {
  const double margin = sigmas * line.bearing_sigma;
  // Camera directions from the foot: (h - w) + pi for h in the bin, widened by the margin:
  // from bin.lo + a to bin.hi + b, rotated with the cached bin trigonometry.
  const Eigen::Vector2d a = Trig(-line.bearing - margin + kPi),
                        b = Trig(-line.bearing + margin + kPi);
  auto rotate = [](const Eigen::Vector2d& x, const Eigen::Vector2d& y) {
    return Eigen::Vector2d(x.x() * y.x() - x.y() * y.y(), x.x() * y.y() + x.y() * y.x());
  };
  for (HeadingBin& bin : region->bins) {
    if (bin.hi - bin.lo + 2.0 * margin >= kPi) continue;
    const Eigen::Vector2d u1 = rotate(bin.trig_lo, a), u2 = rotate(bin.trig_hi, b);
    const Eigen::Vector2d n1(-u1.y(), u1.x()), n2(u2.y(), -u2.x());
    bin.positions.ClipHalfPlane(n1, -n1.dot(edge.foot));
    bin.positions.ClipHalfPlane(n2, -n2.dot(edge.foot));
  }
  DropEmpty(region);
  return !region->Empty();
}

}  // namespace linetrack
