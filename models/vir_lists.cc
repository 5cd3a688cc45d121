// The visibility lists of the view-invariant regions' cells and regions (models/vir_lists.h).
#include "models/vir_lists.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>

#include "models/plan_visibility.h"

namespace linetrack {
namespace {

// Points closer than this are one (metres).
constexpr double kPlanTolerance = 1e-6;
// An occluder farther than this from the hull of a cell and a footprint (metres) hides the
// footprint from no part of the cell: far above the rounding of the cell's splits and the 1e-9 m
// tolerances of HiddenByWall.
constexpr double kHullTolerance = 1e-6;

// True when segments p-q and s meet (touching counts). `d_norm` and `e_norm` are |q - p| and
// |s.b - s.a|.
bool SegmentsMeet(const Eigen::Vector2d& p, const Eigen::Vector2d& q, double d_norm,
                  const Segment2& s, double e_norm) {
  const Eigen::Vector2d d = q - p, e = s.b - s.a;
  // Signed areas s1, s2 of (d, s.a - p) and (d, s.b - p). Where the lines cross, s sits at
  // u = s1 / (s1 - s2); with both ends on one side of line p-q farther than the tolerances below
  // (1e-9 of u, kPlanTolerance for parallel segments), twice over for rounding, they cannot meet.
  const double s1 = Cross2(d, s.a - p), s2 = Cross2(d, s.b - p);
  const double clear = 2.0 * d_norm * std::max(kPlanTolerance, 1e-9 * e_norm);
  if ((s1 > clear && s2 > clear) || (s1 < -clear && s2 < -clear)) return false;
  const double denom = Cross2(d, e);
  if (std::abs(denom) <= 1e-15 * d_norm * e_norm) {
    return DistanceToSegment(p, s) <= kPlanTolerance || DistanceToSegment(q, s) <= kPlanTolerance;
  }
  const double t = Cross2(s.a - p, e) / denom, u = Cross2(s.a - p, d) / denom;
  return t >= -1e-9 && t <= 1.0 + 1e-9 && u >= -1e-9 && u <= 1.0 + 1e-9;
}

Eigen::Vector2d Centre(const Ring2& footprint) {
  Eigen::Vector2d to = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& f : footprint)
    to += f / static_cast<double>(footprint.size());
  return to;
}

// The walls that last hid an edge from one region: the next edges (of the same face, the same
// room) are often hidden by the same walls, found without walking their sight lines.
struct RecentWalls {
  static constexpr int kSize = 4;
  std::array<int, kSize> ids{-1, -1, -1, -1};
  int next = 0;
};

// True when an occluder or a solid hides the whole footprint from the whole region (`from` its
// RingCentroid): only those crossing the line between their centres can (docs/models.md). The walls
// of `recent` that cross it are tried first, and a wall that hides the footprint joins them.
bool Hidden(const Ring2& region, const Eigen::Vector2d& from, const Ring2& footprint,
            const StoreyOccluders& o, double margin, RecentWalls* recent) {
  const Eigen::Vector2d to = Centre(footprint);
  const double sight_length = (to - from).norm();
  const auto hides = [&](int i) {
    const Segment2& wall = o.walls.segments()[i];
    return SegmentsMeet(from, to, sight_length, wall, o.wall_lengths[i]) &&
           HiddenByWall(region, footprint, wall, o.wall_lines[i], margin);
  };
  for (int i : recent->ids) {
    if (i >= 0 && hides(i)) return true;
  }
  int crossed = 0;
  const bool by_wall = o.walls.Along(from, to, [&](int i) {
    const Segment2& wall = o.walls.segments()[i];
    if (!SegmentsMeet(from, to, sight_length, wall, o.wall_lengths[i])) return false;
    ++crossed;
    if (!HiddenByWall(region, footprint, wall, o.wall_lines[i], margin)) return false;
    recent->ids[recent->next] = i;
    recent->next = (recent->next + 1) % RecentWalls::kSize;
    return true;
  });
  if (by_wall) return true;
  // The sight line between the centres is clear: the footprint is in sight. (A solid's sides are
  // occluders: the line meets none of them either.)
  if (crossed == 0) return false;
  ++o.test;
  const bool by_solid = o.solid_sides.Along(from, to, [&](int side) {
    const int solid = o.solid_of_side[side];
    if (o.seen[solid] == o.test) return false;
    o.seen[solid] = o.test;
    return HiddenBySolid(region, from, footprint, o.solids[solid], margin);
  });
  return by_solid;
}

// True when the region (cameras between z_lo and z_hi) lies behind the face's plane by `margin`.
bool Behind(const ModelFace& face, const Ring2& region, double z_lo, double z_hi, double margin) {
  if (face.vertical) {
    const Eigen::Vector2d n = face.normal.head<2>();
    return std::all_of(region.begin(), region.end(),
                       [&](const Eigen::Vector2d& p) { return n.dot(p) - face.offset < -margin; });
  }
  if (face.horizontal) {
    const double z = face.corners.front().z();
    return face.normal.z() > 0.0 ? z > z_hi + margin : z < z_lo - margin;
  }
  return false;
}

// True when the region lies behind every face of the edge, all one-sided.
bool BehindItsFaces(const ModelEdge& edge, const Ring2& region, const WireframeModel& model,
                    const StoreyEdges& edges, double margin) {
  const std::vector<int>& faces = (*edges.one_sided_faces)[edge.id];
  return !faces.empty() && std::all_of(faces.begin(), faces.end(), [&](int f) {
    return Behind(model.faces()[f], region, edges.z_lo, edges.z_hi, margin);
  });
}

// False when no part of the cell (cameras between z_lo and z_hi) can lie behind every face of the
// edge, all one-sided: a vertical face has no vertex of the cell behind it by `margin` (less a
// rounding allowance), or a horizontal face is not behind the band.
bool MaybeBehindItsFaces(const ModelEdge& edge, const Ring2& cell, const WireframeModel& model,
                         const StoreyEdges& edges, double margin) {
  constexpr double kRounding = 1e-9;  // metres
  const std::vector<int>& faces = (*edges.one_sided_faces)[edge.id];
  return !faces.empty() && std::all_of(faces.begin(), faces.end(), [&](int f) {
    const ModelFace& face = model.faces()[f];
    if (!face.vertical) return Behind(face, cell, edges.z_lo, edges.z_hi, margin);
    const Eigen::Vector2d n = face.normal.head<2>();
    return std::any_of(cell.begin(), cell.end(), [&](const Eigen::Vector2d& p) {
      return n.dot(p) - face.offset < -margin + kRounding;
    });
  });
}

// A convex polygon of a few vertices, on the stack.
struct SmallRing {
  static constexpr size_t kCapacity = 64;
  std::array<Eigen::Vector2d, kCapacity> p;
  size_t n = 0;
};

// The part of the convex ring where n.p >= offset - slack (Sutherland-Hodgman): at most one
// vertex more than the ring, which must leave room for it.
void ClipToHalfPlane(const SmallRing& ring, const Eigen::Vector2d& n, double offset, double slack,
                     SmallRing* out) {
  out->n = 0;
  for (size_t i = 0; i < ring.n; ++i) {
    const Eigen::Vector2d &p = ring.p[i], &q = ring.p[(i + 1) % ring.n];
    const double vp = n.dot(p) - offset + slack, vq = n.dot(q) - offset + slack;
    if (vp >= 0.0) out->p[out->n++] = p;
    if ((vp >= 0.0) != (vq >= 0.0)) out->p[out->n++] = p + vp / (vp - vq) * (q - p);
  }
}

// std::nextafter(x, -infinity), by the bits of the float: the next float below x (-0 and +0 step
// to minus the smallest subnormal, +infinity to the largest float; NaN and -infinity stay).
float StepDown(float x) {
  if (!(x > -std::numeric_limits<float>::infinity())) return x;
  if (x == 0.0f) return -std::numeric_limits<float>::denorm_min();
  uint32_t bits = 0;
  std::memcpy(&bits, &x, sizeof bits);
  bits = x > 0.0f ? bits - 1 : bits + 1;
  std::memcpy(&x, &bits, sizeof bits);
  return x;
}

// std::nextafter(x, +infinity).
float StepUp(float x) {
  return -StepDown(-x);
}

// The box of a float box holding [lo, hi].
CellOccluder Occluder(int id, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  return {id, StepDown(static_cast<float>(lo.x())), StepDown(static_cast<float>(lo.y())),
          StepUp(static_cast<float>(hi.x())), StepUp(static_cast<float>(hi.y()))};
}

// A counter-clockwise convex ring and its edges' outward unit normals (none for a zero edge).
struct HullAxes {
  Ring2 hull;
  std::vector<std::pair<Eigen::Vector2d, double>> normals;  // n and n.(a vertex of its edge)
};

// Fills axes->normals from axes->hull.
void ComputeAxes(HullAxes* axes) {
  const Ring2& h = axes->hull;
  axes->normals.clear();
  for (size_t i = 0; i < h.size(); ++i) {
    const Eigen::Vector2d e = h[(i + 1) % h.size()] - h[i];
    const double length = e.norm();
    if (length == 0.0) continue;
    const Eigen::Vector2d n = Eigen::Vector2d(e.y(), -e.x()) / length;
    axes->normals.emplace_back(n, n.dot(h[i]));
  }
}

// SegmentNearConvex with the ring's axes computed once.
bool SegmentNearHull(const HullAxes& axes, const Segment2& s, double tolerance) {
  for (const auto& [n, offset] : axes.normals) {
    if (std::min(n.dot(s.a), n.dot(s.b)) - offset > tolerance) return false;
  }
  const Eigen::Vector2d d = s.b - s.a;
  const double length = d.norm();
  if (length == 0.0) return true;
  const Eigen::Vector2d m = Eigen::Vector2d(d.y(), -d.x()) / length;
  double lo = m.dot(axes.hull.front() - s.a), hi = lo;
  for (const Eigen::Vector2d& p : axes.hull) {
    lo = std::min(lo, m.dot(p - s.a));
    hi = std::max(hi, m.dot(p - s.a));
  }
  return lo <= tolerance && hi >= -tolerance;
}

// The occluders of `footprint` for the cell `ring` (CellList), appended to `out`.
// `points` and `axes` are scratch storage, reused from call to call.
void OccludersOfFootprint(const Ring2& ring, const Ring2& footprint, const StoreyOccluders& o,
                          double margin, Ring2* points, HullAxes* axes,
                          std::vector<CellOccluder>* out) {
  points->assign(ring.begin(), ring.end());
  points->insert(points->end(), footprint.begin(), footprint.end());
  ConvexHull(points, &axes->hull);
  ComputeAxes(axes);
  const Ring2& hull = axes->hull;
  Eigen::Vector2d lo = ring.front(), hi = lo;
  for (const Eigen::Vector2d& p : ring)
    lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  o.walls.InConvex(hull, kHullTolerance, [&](int i) {
    const Segment2& wall = o.walls.segments()[i];
    // HiddenByWall wants the footprint beyond the wall's line by the margin, whatever the region.
    const Line2& line = o.wall_lines[i];
    double f_lo = line.SignedDistance(footprint.front()), f_hi = f_lo;
    for (const Eigen::Vector2d& f : footprint) {
      f_lo = std::min(f_lo, line.SignedDistance(f));
      f_hi = std::max(f_hi, line.SignedDistance(f));
    }
    if (f_hi > -margin && f_lo < margin) return;
    if (!SegmentNearHull(*axes, wall, kHullTolerance)) return;
    Eigen::Vector2d s_lo, s_hi;
    if (ShadowBox(ring, footprint, wall, line, kHullTolerance, &s_lo, &s_hi))
      out->push_back(Occluder(i, s_lo, s_hi));
  });
  ++o.test;
  o.solid_sides.InConvex(hull, kHullTolerance, [&](int side) {
    const int solid = o.solid_of_side[side];
    if (o.seen[solid] == o.test) return;
    if (!SegmentNearHull(*axes, o.solid_sides.segments()[side], kHullTolerance)) return;
    o.seen[solid] = o.test;
    out->push_back(Occluder(-1 - solid, lo, hi));
  });
}

}  // namespace

bool SegmentNearConvex(const Ring2& ring, const Segment2& s, double tolerance) {
  HullAxes axes{ring, {}};
  ComputeAxes(&axes);
  return SegmentNearHull(axes, s, tolerance);
}

bool ShadowBox(const Ring2& ring, const Ring2& footprint, const Segment2& wall, const Line2& line,
               double slack, Eigen::Vector2d* lo, Eigen::Vector2d* hi) {
  // Each of the 1 + 2 |footprint| clips adds at most a vertex.
  if (ring.size() + 2 * footprint.size() + 1 > SmallRing::kCapacity) {
    *lo = *hi = ring.front();  // too many vertices to clip here: the whole ring
    for (const Eigen::Vector2d& p : ring)
      *lo = lo->cwiseMin(p), *hi = hi->cwiseMax(p);
    return true;
  }
  SmallRing parts[2];
  int now = 0;
  parts[now].n = ring.size();
  std::copy(ring.begin(), ring.end(), parts[now].p.begin());
  const auto clip = [&](const Eigen::Vector2d& n, double offset) {
    ClipToHalfPlane(parts[now], n, offset, slack, &parts[1 - now]);
    now = 1 - now;
    return parts[now].n > 0;
  };
  // The far side of the line from the footprint.
  const double side = line.SignedDistance(footprint.front()) < 0.0 ? 1.0 : -1.0;
  if (!clip(side * line.normal, side * line.offset)) return false;
  const Eigen::Vector2d d = line.Direction();
  const Eigen::Vector2d a = wall.a - slack * d, b = wall.b + slack * d;
  for (const Eigen::Vector2d& f : footprint) {
    // The cone from f through a and b: on b's side of line f-a and on a's side of line f-b.
    const double turn = Cross2(a - f, b - f) > 0.0 ? 1.0 : -1.0;
    const Eigen::Vector2d ea = (a - f).normalized(), eb = (b - f).normalized();
    const Eigen::Vector2d na = turn * Eigen::Vector2d(-ea.y(), ea.x());
    const Eigen::Vector2d nb = -turn * Eigen::Vector2d(-eb.y(), eb.x());
    if (!clip(na, na.dot(f)) || !clip(nb, nb.dot(f))) return false;
  }
  const SmallRing& part = parts[now];
  *lo = *hi = part.p[0];
  for (size_t i = 0; i < part.n; ++i)
    *lo = lo->cwiseMin(part.p[i]), *hi = hi->cwiseMax(part.p[i]);
  return true;
}

CellList CellVisibility(const Ring2& ring, const WireframeModel& model, const StoreyEdges& edges,
                        const StoreyOccluders& occluders, double margin, CellOccluders keep) {
  CellList list;
  const bool kept = keep == CellOccluders::kKeep;
  if (kept) list.first.push_back(0);
  const Eigen::Vector2d centre = RingCentroid(ring);
  Ring2 points;
  HullAxes axes;
  RecentWalls recent;
  // Per footprint (its first entry, StoreyEdges::same_as): not decided yet, hidden, or in sight,
  // with the list index of the first edge listed with it (whose occluders it shares).
  constexpr int kUndecided = -1, kHidden = -2;
  std::vector<int> decided(edges.ids.size(), kUndecided);
  for (size_t k = 0; k < edges.ids.size(); ++k) {
    const ModelEdge& edge = model.edges()[edges.ids[k]];
    if (BehindItsFaces(edge, ring, model, edges, margin)) continue;
    const Ring2& footprint = edges.footprints[k];
    if (edges.in_band[k]) {
      int& state = decided[edges.same_as[k]];
      if (state == kHidden) continue;
      if (state == kUndecided) {
        if (Hidden(ring, centre, footprint, occluders, margin, &recent)) {
          state = kHidden;
          continue;
        }
        state = static_cast<int>(list.edges.size());
        if (kept)
          OccludersOfFootprint(ring, footprint, occluders, margin, &points, &axes, &list.occluders);
      } else if (kept) {
        for (int i = list.first[state]; i < list.first[state + 1]; ++i) {
          const CellOccluder copy = list.occluders[i];
          list.occluders.push_back(copy);
        }
      }
    }
    list.edges.push_back(static_cast<int>(k));
    if (kept) {
      list.first.push_back(static_cast<int>(list.occluders.size()));
      list.maybe_behind.push_back(MaybeBehindItsFaces(edge, ring, model, edges, margin) ? 1 : 0);
    }
  }
  return list;
}

std::vector<RegionEdge> DirectVisibility(const Cell& region, const WireframeModel& model,
                                         const StoreyEdges& edges, const StoreyOccluders& occluders,
                                         double margin) {
  CellList all;
  all.edges.resize(edges.ids.size());
  std::iota(all.edges.begin(), all.edges.end(), 0);
  return RegionVisibility(region, model, edges, all, occluders, margin);
}

std::vector<RegionEdge> RegionVisibility(const Cell& region, const WireframeModel& model,
                                         const StoreyEdges& edges, const CellList& cell,
                                         const StoreyOccluders& occluders, double margin) {
  std::vector<RegionEdge> visible;
  visible.reserve(cell.edges.size());
  const Ring2& ring = region.ring;
  const Eigen::Vector2d centroid = RingCentroid(ring);
  const bool walk = cell.first.empty();
  RecentWalls recent;
  // Per footprint (StoreyEdges::same_as): not decided yet, hidden, or the index in `visible` of
  // the first edge listed with it, whose bearings it shares.
  constexpr int kUndecided = -1, kHidden = -2;
  std::vector<int> decided(edges.ids.size(), kUndecided);
  for (size_t j = 0; j < cell.edges.size(); ++j) {
    const int k = cell.edges[j];
    const ModelEdge& edge = model.edges()[edges.ids[k]];
    if ((walk || cell.maybe_behind[j]) && BehindItsFaces(edge, ring, model, edges, margin))
      continue;
    int& state = decided[edges.same_as[k]];
    if (state == kHidden) continue;
    if (state >= 0) {
      RegionEdge listed = visible[state];
      listed.edge_id = edge.id;
      visible.push_back(listed);
      continue;
    }
    const Ring2& footprint = edges.footprints[k];
    // An occluder hides the edge from the region only when it hides it from all its points: the
    // region lies in the occluder's box.
    const auto hides = [&](const CellOccluder& o) {
      if (region.lo.x() < o.lo_x || region.lo.y() < o.lo_y || region.hi.x() > o.hi_x ||
          region.hi.y() > o.hi_y) {
        return false;
      }
      return o.id >= 0
                 ? HiddenByWall(ring, footprint, occluders.walls.segments()[o.id],
                                occluders.wall_lines[o.id], margin)
                 : HiddenBySolid(ring, centroid, footprint, occluders.solids[-1 - o.id], margin);
    };
    if (edges.in_band[k] &&
        (walk ? Hidden(ring, centroid, footprint, occluders, margin, &recent)
              : std::any_of(cell.occluders.data() + cell.first[j],
                            cell.occluders.data() + cell.first[j + 1], hides))) {
      state = kHidden;
      continue;
    }
    state = static_cast<int>(visible.size());
    const BearingRange range = BearingsToFootprint(ring, region.lo, region.hi, footprint);
    RegionEdge& listed = visible.emplace_back();
    listed.edge_id = edge.id;
    listed.all_bearings = range.all;
    listed.diamond_min = range.min;
    listed.diamond_max = range.max;
  }
  return visible;
}

}  // namespace linetrack
