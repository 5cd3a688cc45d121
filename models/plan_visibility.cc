#include "models/plan_visibility.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace linetrack {
namespace {

// Region points on an occluder's line count as touching it within this (metres), and a chord may
// end this far past the occluder's ends (sight lines through its very end are measure zero).
constexpr double kTouch = 1e-9;
// Boxes this far apart (metres) hold no two points within kTouch, whatever the rounding.
constexpr double kApart = 1e-6;

double Support(const Ring2& points, const Eigen::Vector2d& n) {
  double best = -std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& p : points)
    best = std::max(best, n.dot(p));
  return best;
}

// True when test(n) holds for an outward unit normal n of a counter-clockwise ring's edges (both
// normals for a two-point footprint); the normals are tried in order, the first true stops.
template <typename Test>
bool AnyEdgeNormal(const Ring2& ring, const Test& test) {
  if (ring.size() == 2) {
    const Eigen::Vector2d d = ring[1] - ring[0];
    if (!(d.norm() > 0.0)) return false;
    const Eigen::Vector2d n = Eigen::Vector2d(d.y(), -d.x()).normalized();
    return test(n) || test(-n);
  }
  for (size_t i = 0; i < ring.size(); ++i) {
    const Eigen::Vector2d d = ring[(i + 1) % ring.size()] - ring[i];
    if (d.norm() > 0.0 && test(Eigen::Vector2d(d.y(), -d.x()).normalized())) return true;
  }
  return false;
}

// False when the boxes of the region ([r_lo, r_hi]) and the footprint are too far apart for the
// footprint to meet the region or come within kTouch of it.
bool MayTouch(const Eigen::Vector2d& r_lo, const Eigen::Vector2d& r_hi, const Ring2& footprint) {
  Eigen::Vector2d f_lo = footprint.front(), f_hi = f_lo;
  for (const Eigen::Vector2d& f : footprint)
    f_lo = f_lo.cwiseMin(f), f_hi = f_hi.cwiseMax(f);
  return (f_lo - r_hi).maxCoeff() <= kApart && (r_lo - f_hi).maxCoeff() <= kApart;
}

}  // namespace

std::vector<std::pair<double, double>> FullHeightSpans(const Ring2& s_z, double z_lo, double z_hi) {
  std::vector<double> xs;
  for (const Eigen::Vector2d& p : s_z)
    xs.push_back(p.x());
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
  std::vector<std::pair<double, double>> covered;
  for (size_t k = 0; k + 1 < xs.size(); ++k) {
    const double s0 = xs[k], s1 = xs[k + 1];
    if (s1 - s0 < 1e-9) continue;
    // Inside the slab the polygon's edges are straight lines z(s); the band is covered where no
    // edge passes through it and the band's middle is inside.
    std::vector<std::pair<double, double>> blocked;
    for (size_t i = 0; i < s_z.size(); ++i) {
      const Eigen::Vector2d& p = s_z[i];
      const Eigen::Vector2d& q = s_z[(i + 1) % s_z.size()];
      if (std::min(p.x(), q.x()) > s0 || std::max(p.x(), q.x()) < s1) continue;
      const double slope = (q.y() - p.y()) / (q.x() - p.x());
      const double za = p.y() + slope * (s0 - p.x()), zb = p.y() + slope * (s1 - p.x());
      if (std::max(za, zb) <= z_lo || std::min(za, zb) >= z_hi) continue;  // outside the band
      double lo = s0, hi = s1;
      if (slope != 0.0) {
        const double sa = s0 + (z_lo - za) / slope, sb = s0 + (z_hi - za) / slope;
        lo = std::max(s0, std::min(sa, sb));
        hi = std::min(s1, std::max(sa, sb));
      }
      blocked.emplace_back(lo, hi);
    }
    std::sort(blocked.begin(), blocked.end());
    double start = s0;
    auto keep = [&](double a, double b) {
      if (b - a < 1e-9) return;
      if (!RingContains(s_z, {0.5 * (a + b), 0.5 * (z_lo + z_hi)})) return;
      if (!covered.empty() && a - covered.back().second < 1e-9) {
        covered.back().second = b;
      } else {
        covered.emplace_back(a, b);
      }
    };
    for (const auto& [lo, hi] : blocked) {
      keep(start, lo);
      start = std::max(start, hi);
    }
    keep(start, s1);
  }
  return covered;
}

std::vector<Segment2> FullHeightOccluders(const WireframeModel& model, double tolerance,
                                          double camera_top) {
  return OccludersInBand(model, model.BoxMin().z() + tolerance,
                         std::max(model.BoxMax().z(), camera_top) - tolerance);
}

WallInPlane ToWallPlane(const ModelFace& face) {
  WallInPlane wall;
  const Eigen::Vector2d n = face.normal.head<2>().normalized();
  wall.along = Eigen::Vector2d(-n.y(), n.x());
  wall.origin = face.corners.front().head<2>();
  wall.z_lo = std::numeric_limits<double>::infinity();
  wall.z_hi = -wall.z_lo;
  for (const Eigen::Vector3d& c : face.corners) {
    wall.s_z.emplace_back(wall.along.dot(c.head<2>() - wall.origin), c.z());
    wall.z_lo = std::min(wall.z_lo, c.z());
    wall.z_hi = std::max(wall.z_hi, c.z());
  }
  return wall;
}

std::vector<Segment2> OccludersInBand(const WireframeModel& model, double z_lo, double z_hi) {
  std::vector<Segment2> pieces;
  if (!(z_hi > z_lo)) return pieces;
  for (const ModelFace& face : model.faces()) {
    if (!face.vertical || face.Degenerate()) continue;
    const WallInPlane wall = ToWallPlane(face);
    for (const auto& [s0, s1] : FullHeightSpans(wall.s_z, z_lo, z_hi))
      pieces.push_back({wall.At(s0), wall.At(s1)});
  }
  return MergeCollinear(pieces, 1e-6);
}

std::vector<Segment2> MergeCollinear(const std::vector<Segment2>& segments, double tolerance) {
  struct Group {
    Line2 line;
    std::vector<std::pair<double, double>> spans;  // along line.Direction()
  };
  std::vector<Group> groups;
  for (const Segment2& s : segments) {
    if (s.Length() <= tolerance) continue;
    Group* group = nullptr;
    for (Group& g : groups) {
      if (std::abs(g.line.SignedDistance(s.a)) <= tolerance &&
          std::abs(g.line.SignedDistance(s.b)) <= tolerance) {
        group = &g;
        break;
      }
    }
    if (group == nullptr) {
      groups.push_back({Line2::Through(s.a, s.b), {}});
      group = &groups.back();
    }
    const Eigen::Vector2d d = group->line.Direction();
    group->spans.emplace_back(std::min(d.dot(s.a), d.dot(s.b)), std::max(d.dot(s.a), d.dot(s.b)));
  }
  std::vector<Segment2> merged;
  for (Group& g : groups) {
    std::sort(g.spans.begin(), g.spans.end());
    const Eigen::Vector2d d = g.line.Direction(), base = g.line.offset * g.line.normal;
    std::pair<double, double> run = g.spans.front();
    auto emit = [&] { merged.push_back({base + run.first * d, base + run.second * d}); };
    for (size_t i = 1; i < g.spans.size(); ++i) {
      if (g.spans[i].first <= run.second + tolerance) {
        run.second = std::max(run.second, g.spans[i].second);
      } else {
        emit();
        run = g.spans[i];
      }
    }
    emit();
  }
  return merged;
}

bool HiddenByWall(const Ring2& region, const Ring2& footprint, const Segment2& wall,
                  double margin) {
  return HiddenByWall(region, footprint, wall, Line2::Through(wall.a, wall.b), margin);
}

bool HiddenByWall(const Ring2& region, const Ring2& footprint, const Segment2& wall,
                  const Line2& line, double margin) {
  // The footprint picks the side (it cannot be `margin` beyond both); the region must be on the
  // other, every vertex within kTouch.
  double f_lo = std::numeric_limits<double>::infinity(), f_hi = -f_lo;
  for (const Eigen::Vector2d& f : footprint) {
    f_lo = std::min(f_lo, line.SignedDistance(f));
    f_hi = std::max(f_hi, line.SignedDistance(f));
  }
  const double sign = f_hi <= -margin ? 1.0 : f_lo >= margin ? -1.0 : 0.0;
  if (sign == 0.0) return false;
  for (const Eigen::Vector2d& r : region) {
    if (sign * line.SignedDistance(r) < -kTouch) return false;
  }
  // The chord conv(region + footprint) n line, inside the wall: region points on the line and the
  // crossings of the segments between the two sides' vertices.
  const Eigen::Vector2d d = line.Direction();
  const double lo = d.dot(wall.a) - kTouch, hi = d.dot(wall.b) + kTouch;
  for (const Eigen::Vector2d& r : region) {
    const double sr = sign * line.SignedDistance(r);
    if (sr <= kTouch) {
      const double x = d.dot(r);
      if (x < lo || x > hi) return false;
      continue;
    }
    for (const Eigen::Vector2d& f : footprint) {
      const double sf = sign * line.SignedDistance(f);
      const double x = d.dot(r + sr / (sr - sf) * (f - r));
      if (x < lo || x > hi) return false;
    }
  }
  return true;
}

std::vector<std::vector<WallCorner>> WallCorners(const std::vector<Segment2>& walls,
                                                 double tolerance) {
  std::vector<std::vector<WallCorner>> corners(walls.size());
  for (size_t i = 0; i < walls.size(); ++i) {
    for (size_t j = i + 1; j < walls.size(); ++j) {
      const Eigen::Vector2d u = walls[i].b - walls[i].a, v = walls[j].b - walls[j].a;
      if (std::abs(Cross2(u.normalized(), v.normalized())) < 1e-9) continue;  // collinear
      const Segment2 ends_i[2] = {walls[i], {walls[i].b, walls[i].a}};
      const Segment2 ends_j[2] = {walls[j], {walls[j].b, walls[j].a}};
      for (const Segment2& e : ends_i) {  // e.a the end that may meet, e.b the far one
        for (const Segment2& f : ends_j) {
          if ((e.a - f.a).norm() > tolerance) continue;
          corners[i].push_back({e.a, e.b, f.b});
          corners[j].push_back({f.a, f.b, e.b});
        }
      }
    }
  }
  return corners;
}

bool HiddenByCorner(const Ring2& region, const Ring2& footprint, const Eigen::Vector2d& corner,
                    const Eigen::Vector2d& far_a, const Eigen::Vector2d& far_b, double margin) {
  // Continued past the corner far beyond any sight line: a chord on a continuation lies on the
  // other wall's far side, and its sight line met the other wall before (docs/models.md).
  constexpr double kBeyond = 1e4;  // metres
  const Line2 line_a = Line2::Through(far_a, corner), line_b = Line2::Through(far_b, corner);
  // The footprint's side of each line; the other wall's far end must lie on the region's side.
  double f_a = 0.0, f_b = 0.0;
  for (const Eigen::Vector2d& f : footprint) {
    f_a += line_a.SignedDistance(f);
    f_b += line_b.SignedDistance(f);
  }
  if (!(f_a * line_a.SignedDistance(far_b) < 0.0 && f_b * line_b.SignedDistance(far_a) < 0.0)) {
    return false;
  }
  const Segment2 wall_a{far_a, corner + kBeyond * (corner - far_a).normalized()};
  const Segment2 wall_b{far_b, corner + kBeyond * (corner - far_b).normalized()};
  return HiddenByWall(region, footprint, wall_a, line_a, margin) &&
         HiddenByWall(region, footprint, wall_b, line_b, margin);
}

bool HiddenBySolid(const Ring2& region, const Ring2& footprint, const Ring2& solid, double margin) {
  return HiddenBySolid(region, RingCentroid(region), footprint, solid, margin);
}

bool HiddenBySolid(const Ring2& region, const Eigen::Vector2d& region_centroid,
                   const Ring2& footprint, const Ring2& solid, double margin) {
  if (!ConvexInteriorsDisjoint(region, solid, kTouch)) return false;
  // Cheap necessary condition first: the sight line between the centres crosses the solid.
  Eigen::Vector2d f_mid = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& f : footprint)
    f_mid += f / static_cast<double>(footprint.size());
  const Segment2 centre_line{region_centroid, f_mid};
  double t0 = 0.0, t1 = 0.0;
  if (!ClipSegmentToConvex(solid, centre_line, &t0, &t1) ||
      (t1 - t0) * centre_line.Length() < margin) {
    return false;
  }
  // g(n) = min(h_R(n), h_F(n)) - h_P(n) is piecewise a min of two sinusoids between the edge
  // normals; its maximum lies at an edge normal, at a stationary point (n along r - v or f - v)
  // or where the two sinusoids cross (n orthogonal to r - f). Each candidate n is tested as it
  // comes: the first with g(n) > -margin decides.
  const auto separates = [&](const Eigen::Vector2d& n) {
    return std::min(Support(region, n), Support(footprint, n)) > Support(solid, n) - margin;
  };
  const auto direction_separates = [&](const Eigen::Vector2d& v) {
    const double norm = v.norm();
    return norm > 1e-15 && separates(v / norm);
  };
  if (AnyEdgeNormal(region, separates) || AnyEdgeNormal(footprint, separates) ||
      AnyEdgeNormal(solid, separates)) {
    return false;
  }
  for (const Eigen::Vector2d& v : solid) {
    for (const Eigen::Vector2d& r : region) {
      if (direction_separates(r - v)) return false;
    }
    for (const Eigen::Vector2d& f : footprint) {
      if (direction_separates(f - v)) return false;
    }
  }
  for (const Eigen::Vector2d& r : region) {
    for (const Eigen::Vector2d& f : footprint) {
      const Eigen::Vector2d d = r - f;
      if (direction_separates({d.y(), -d.x()}) || direction_separates({-d.y(), d.x()}))
        return false;
    }
  }
  return true;
}

bool ClipToBearingWedge(const Segment2& footprint, const Eigen::Vector2d& centre, double radius,
                        double heading, double half, Segment2* part) {
  *part = footprint;
  if (!(2.0 * half < kPi)) return true;
  // A point p seen under bearing b from e in the disk: p - e is counter-clockwise of the arc's
  // first direction u1 and clockwise of its last u2, so n.(p - centre) >= n.(e - centre) >= -r
  // for n = u1 turned left and for n = u2 turned right.
  const double b1 = heading - half, b2 = heading + half;
  const Eigen::Vector2d normals[2] = {{-std::sin(b1), std::cos(b1)}, {std::sin(b2), -std::cos(b2)}};
  double t0 = 0.0, t1 = 1.0;
  const Eigen::Vector2d d = footprint.b - footprint.a;
  for (const Eigen::Vector2d& n : normals) {
    // g(t) = n.(a + t d - centre) + r (+ rounding) >= 0 on the part.
    const double g0 = n.dot(footprint.a - centre) + radius + kTouch, slope = n.dot(d);
    if (slope == 0.0) {
      if (g0 < 0.0) return false;
      continue;
    }
    const double t = -g0 / slope;
    if (slope > 0.0) t0 = std::max(t0, t);
    if (slope < 0.0) t1 = std::min(t1, t);
  }
  if (t0 > t1) return false;
  *part = {footprint.a + t0 * d, footprint.a + t1 * d};
  return true;
}

Ring2 PolygonAroundDisk(const Eigen::Vector2d& centre, double radius, int sides) {
  // The inscribed circle of a regular polygon of circumradius R is R cos(pi / sides).
  const double circumradius = radius / std::cos(kPi / sides) + kTouch;
  Ring2 ring;
  for (int k = 0; k < sides; ++k) {
    const double a = 2.0 * kPi * k / sides;
    ring.push_back(centre + circumradius * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  return ring;
}

BearingRange BearingsToFootprint(const Ring2& region, const Ring2& footprint) {
  Eigen::Vector2d lo = region.front(), hi = lo;
  for (const Eigen::Vector2d& r : region)
    lo = lo.cwiseMin(r), hi = hi.cwiseMax(r);
  return BearingsToFootprint(region, lo, hi, footprint);
}

BearingRange BearingsToFootprint(const Ring2& region, const Eigen::Vector2d& region_lo,
                                 const Eigen::Vector2d& region_hi, const Ring2& footprint) {
  BearingRange range;
  range.all = true;
  const bool may_touch = MayTouch(region_lo, region_hi, footprint);
  if (may_touch) {
    if (footprint.size() == 1) {
      if (ConvexContains(region, footprint[0], kTouch)) return range;
    } else {
      double t0 = 0.0, t1 = 0.0;
      const Segment2 s{footprint[0], footprint[1]};
      if (ClipSegmentToConvex(region, s, &t0, &t1)) return range;
      for (size_t i = 0; i < region.size(); ++i) {
        const Segment2 edge{region[i], region[(i + 1) % region.size()]};
        if (DistanceToSegment(edge.a, s) <= kTouch || DistanceToSegment(s.a, edge) <= kTouch ||
            DistanceToSegment(s.b, edge) <= kTouch) {
          return range;
        }
      }
    }
  }
  // The vectors q - p form a convex set without the origin: their directions span less than a
  // half turn, where Cross2 orders them exactly as their bearings, and the extremes are differences
  // of vertices. Only the two extremes take a diamond angle.
  Eigen::Vector2d lo_v = footprint.front() - region.front(), hi_v = lo_v;
  for (const Eigen::Vector2d& f : footprint) {
    for (const Eigen::Vector2d& r : region) {
      const Eigen::Vector2d v = f - r;
      if (may_touch && v.squaredNorm() <= kTouch * kTouch) return range;
      if (Cross2(v, lo_v) > 0.0) lo_v = v;  // clockwise of the lowest so far
      if (Cross2(hi_v, v) > 0.0) hi_v = v;
    }
  }
  const double lo = DiamondAngle(lo_v);
  double width = WrapDiamond(DiamondAngle(hi_v) - lo);
  if (width > 3.0) width = 0.0;  // hi_v within rounding of lo_v, its diamond angle just below
  if (width >= 2.0 - 1e-9) return range;
  range.all = false;
  range.min = lo;
  range.max = lo + width;
  return range;
}

}  // namespace linetrack
