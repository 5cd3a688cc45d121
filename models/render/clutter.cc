#include "models/render/clutter.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "models/render/frame_decals.h"
#include "models/render/procedural.h"

namespace linetrack {
namespace {

constexpr double kWallGap = 0.01;     // metres between a box's back and its wall
constexpr double kPosterGap = 0.005;  // metres between a poster and its wall
constexpr double kMinBoxDepth = 0.12;

struct Aabb {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;

  void Add(const Eigen::Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  bool Overlaps(const Aabb& o, double margin) const {
    return (lo.array() - margin <= o.hi.array()).all() &&
           (o.lo.array() <= hi.array() + margin).all();
  }
  // Slab test of the segment a-b against the box grown by `margin`.
  bool Hit(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double margin) const {
    double t0 = 0.0, t1 = 1.0;
    for (int k = 0; k < 3; ++k) {
      const double d = b[k] - a[k], l = lo[k] - margin, h = hi[k] + margin;
      if (std::abs(d) < 1e-12) {
        if (a[k] < l || a[k] > h) return false;
        continue;
      }
      double ta = (l - a[k]) / d, tb = (h - a[k]) / d;
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      if (t0 > t1) return false;
    }
    return true;
  }
};

bool FreeAt(const NavigableArea& area, const Eigen::Vector3d& p) {
  return area.InsideBoundary(p.head<2>());
}

RenderSurface Solid(std::vector<Eigen::Vector3d> polygon, double albedo, bool decal = false) {
  RenderSurface s = PlanarSurface(std::move(polygon), SurfaceKind::kClutter, albedo);
  s.decal = decal;
  return s;
}

// A decal band on `host` from p to q, `width` metres wide, centred.
RenderSurface Band(const RenderSurface& host, const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                   double width, double albedo) {
  const Eigen::Vector3d across = host.normal.cross((q - p).normalized()) * (0.5 * width);
  RenderSurface band =
      Solid({p - across, q - across, q + across, p + across}, albedo, /*decal=*/true);
  band.normal = host.normal;  // the host's exact plane, so the decal depth test matches bit for bit
  band.offset = host.offset;
  return band;
}

// A vertical face as a frame: X(s, z, depth) = n offset + s e1 + z up + depth side n.
struct Wall {
  const ModelFace* face = nullptr;
  Eigen::Vector3d e1, e2;
  double s_min = 0.0, s_max = 0.0, z_min = 0.0, z_max = 0.0;
  double side = 1.0;

  Eigen::Vector3d At(double s, double z, double depth) const {
    return face->normal * face->offset + s * e1 + z * Eigen::Vector3d::UnitZ() +
           depth * side * face->normal;
  }
  bool OnFace(double s, double z) const {
    Eigen::Vector3d b1, b2;
    PlaneBasis(face->normal, &b1, &b2);
    return InsidePlanarPolygon(face->corners, At(s, z, 0.0), b1, b2);
  }
};

struct Item {
  std::vector<RenderSurface> surfaces;
  Aabb box;
  std::vector<Eigen::Vector3d> in_room;  // points that must lie in free space
};

Item MakeBox(const Wall& w, double s0, double width, double height, double depth, double albedo) {
  const double d0 = kWallGap, d1 = kWallGap + depth, s1 = s0 + width;
  auto p = [&](double s, double z, double d) { return w.At(s, z, d); };
  Item item;
  item.surfaces = {
      Solid({p(s0, 0, d1), p(s1, 0, d1), p(s1, height, d1), p(s0, height, d1)}, albedo),
      Solid({p(s0, 0, d0), p(s0, 0, d1), p(s0, height, d1), p(s0, height, d0)}, albedo - 0.04),
      Solid({p(s1, 0, d0), p(s1, 0, d1), p(s1, height, d1), p(s1, height, d0)}, albedo - 0.04),
      Solid({p(s0, height, d0), p(s1, height, d0), p(s1, height, d1), p(s0, height, d1)},
            albedo + 0.06),
  };
  for (double s : {s0, s1})
    for (double z : {0.0, height})
      for (double d : {d0, d1})
        item.box.Add(p(s, z, d));
  item.in_room = {p(s0, 0, d1), p(s1, 0, d1), p(0.5 * (s0 + s1), 0, d1)};
  return item;
}

// Tries to place one object of a random kind on wall `w`; false when it does not fit.
bool TryPlace(const Wall& w, double clearance, SeededDraws* draws, Item* item) {
  const double kind = draws->Unit();
  const double room = w.s_max - w.s_min - 0.1;
  const double box_depth = std::min(0.5, clearance - 0.03);
  if (kind < 0.5 || kind >= 0.8) {  // a box (50 %) or a cabinet (20 %)
    const bool cabinet = kind >= 0.8;
    const double width = cabinet ? draws->Uniform(0.7, 1.2) : draws->Uniform(0.35, 0.9);
    const double height = cabinet ? draws->Uniform(1.6, 2.0) : draws->Uniform(0.3, 0.8);
    const double depth = cabinet ? box_depth : draws->Uniform(0.6, 1.0) * box_depth;
    if (depth < kMinBoxDepth || width > room || w.z_min > 0.01) return false;
    const double s0 = draws->Uniform(w.s_min + 0.05, w.s_max - 0.05 - width);
    if (!w.OnFace(s0, 0.005) || !w.OnFace(s0 + width, height) || !w.OnFace(s0, height) ||
        !w.OnFace(s0 + width, 0.005)) {
      return false;
    }
    const double albedo =
        cabinet ? (draws->Unit() < 0.5 ? draws->Uniform(0.15, 0.3) : draws->Uniform(0.8, 0.9))
                : draws->Uniform(0.45, 0.7);
    *item = MakeBox(w, s0, width, height, depth, albedo);
    if (cabinet) {  // two doors and a drawer line on the front
      const RenderSurface front = item->surfaces[0];
      const double line = albedo > 0.5 ? 0.12 : 0.75;
      const double d = kWallGap + depth;
      item->surfaces.push_back(Band(front, w.At(s0 + 0.5 * width, 0.05, d),
                                    w.At(s0 + 0.5 * width, 0.7 * height, d), 0.012, line));
      item->surfaces.push_back(Band(front, w.At(s0 + 0.03, 0.7 * height, d),
                                    w.At(s0 + width - 0.03, 0.7 * height, d), 0.012, line));
    }
    return true;
  }
  // A poster with a picture on it (30 %).
  const double width = draws->Uniform(0.4, 0.9), height = draws->Uniform(0.5, 1.0);
  const double zc = draws->Uniform(1.2, 1.8);
  if (width > room) return false;
  const double s0 = draws->Uniform(w.s_min + 0.05, w.s_max - 0.05 - width), s1 = s0 + width;
  const double z0 = zc - 0.5 * height, z1 = zc + 0.5 * height;
  if (!w.OnFace(s0, z0) || !w.OnFace(s1, z0) || !w.OnFace(s1, z1) || !w.OnFace(s0, z1)) {
    return false;
  }
  const double albedo = draws->Uniform(0.08, 0.95);
  const double contrast = draws->Uniform(0.3, 0.6);
  const double picture = albedo > 0.5 ? albedo - contrast : albedo + contrast;
  const double m = draws->Uniform(0.05, 0.1);
  auto p = [&](double s, double z) { return w.At(s, z, kPosterGap); };
  item->surfaces = {Solid({p(s0, z0), p(s1, z0), p(s1, z1), p(s0, z1)}, albedo)};
  RenderSurface inner =
      Solid({p(s0 + m, z0 + m), p(s1 - m, z0 + m), p(s1 - m, z1 - 2 * m), p(s0 + m, z1 - 2 * m)},
            picture, /*decal=*/true);
  inner.normal = item->surfaces[0].normal;
  inner.offset = item->surfaces[0].offset;
  item->surfaces.push_back(inner);
  item->box = Aabb();
  for (const Eigen::Vector3d& c : item->surfaces[0].polygon)
    item->box.Add(c);
  return true;
}

}  // namespace

std::vector<RenderSurface> PlaceClutter(const WireframeModel& model,
                                        const NavigableArea& free_space, int count, double margin,
                                        uint64_t seed, int* placed) {
  std::vector<Wall> walls;
  std::vector<double> cumulative;
  double total = 0.0;
  for (const ModelFace& face : model.faces()) {
    if (face.Degenerate() || !face.vertical) continue;
    Wall w;
    w.face = &face;
    PlaneBasis(face.normal, &w.e1, &w.e2);
    w.s_min = w.z_min = std::numeric_limits<double>::infinity();
    w.s_max = w.z_max = -w.s_min;
    for (const Eigen::Vector3d& c : face.corners) {
      w.s_min = std::min(w.s_min, w.e1.dot(c));
      w.s_max = std::max(w.s_max, w.e1.dot(c));
      w.z_min = std::min(w.z_min, c.z());
      w.z_max = std::max(w.z_max, c.z());
    }
    if (w.s_max - w.s_min < 0.5) continue;
    total += w.s_max - w.s_min;
    walls.push_back(w);
    cumulative.push_back(total);
  }
  SeededDraws draws(HashCombine(seed, 0xc1077e4ull));
  std::vector<Item> items;
  for (int attempt = 0;
       attempt < 50 * count && static_cast<int>(items.size()) < count && !walls.empty();
       ++attempt) {
    const double pick = draws.Uniform(0.0, total);
    Wall w =
        walls[std::lower_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin()];
    // The room side: free space 0.3 m off the middle of the wall.
    const double s_mid = 0.5 * (w.s_min + w.s_max);
    w.side = 1.0;
    const bool plus = FreeAt(free_space, w.At(s_mid, 0.0, 0.3));
    w.side = -1.0;
    const bool minus = FreeAt(free_space, w.At(s_mid, 0.0, 0.3));
    if (!plus && !minus) continue;
    w.side = plus && minus ? (draws.Unit() < 0.5 ? 1.0 : -1.0) : (plus ? 1.0 : -1.0);
    Item item;
    if (!TryPlace(w, free_space.clearance(), &draws, &item)) continue;
    bool ok = true;
    for (const Eigen::Vector3d& p : item.in_room)
      ok = ok && FreeAt(free_space, p);
    for (const ModelEdge& e : model.edges()) {
      if (e.from_line && item.box.Hit(e.segment.a, e.segment.b, margin)) ok = false;
    }
    for (const Item& other : items)
      ok = ok && !item.box.Overlaps(other.box, margin);
    if (ok) items.push_back(std::move(item));
  }
  std::vector<RenderSurface> out;
  for (const Item& item : items)
    out.insert(out.end(), item.surfaces.begin(), item.surfaces.end());
  if (placed) *placed = static_cast<int>(items.size());
  return out;
}

}  // namespace linetrack
