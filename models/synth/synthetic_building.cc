#include "models/synth/synthetic_building.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "models/errors.h"

namespace linetrack {
namespace {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

// Room widths along the corridor (metres), repeated; the north side takes them in reverse order.
constexpr std::array<double, 9> kRoomWidths = {4.0, 3.6, 4.4, 5.0, 3.8, 4.2, 4.6, 3.6, 4.8};
// Windows: sill and head above the floor, width (metres).
constexpr double kSillHeight = 0.9, kWindowHead = 2.1, kWindowWidth = 1.4;
// Door casings: lines this far outside the opening on both faces of the wall (metres).
constexpr double kCasing = 0.08;
// Radiators under the windows: height, depth off the wall (metres); ceiling light panels: side.
constexpr double kRadiatorHeight = 0.6, kRadiatorDepth = 0.12, kLightSide = 0.6;

// Collects points (each distinct point once), lines and faces.
class CaoBuilder {
 public:
  int Point(const Vec3& p) {
    const std::array<long long, 3> key = {std::llround(p.x() * 1e6), std::llround(p.y() * 1e6),
                                          std::llround(p.z() * 1e6)};
    const auto [it, fresh] = index_.emplace(key, static_cast<int>(cao_.points.size()));
    if (fresh) cao_.points.push_back(p);
    return it->second;
  }
  void Line(const Vec3& a, const Vec3& b) { cao_.lines.push_back({Point(a), Point(b)}); }
  void Face(const std::vector<Vec3>& corners) {
    std::vector<int> ids;
    for (const Vec3& c : corners)
      ids.push_back(Point(c));
    cao_.faces.push_back(std::move(ids));
  }
  CaoModel Take(const std::string& name) {
    cao_.files = {name};
    return std::move(cao_);
  }

 private:
  std::map<std::array<long long, 3>, int> index_;
  CaoModel cao_;
};

// A vertical face over the floor segment a -> b from z0 to z1, with door notches [s0, s1]
// (metres from a) up to z0 + notch_height; its normal on the left of a -> b (a room walked
// counter-clockwise) or, with `face_right`, on the right (a solid walked counter-clockwise).
void WallFace(CaoBuilder* b, const Vec2& from, const Vec2& to, double z0, double z1,
              std::vector<std::array<double, 2>> notches, double notch_height, bool face_right) {
  const Vec2 d = (to - from).normalized();
  const double length = (to - from).norm();
  std::sort(notches.begin(), notches.end());
  // Counter-clockwise in (s, z) gives the normal on the right of a -> b.
  std::vector<Vec2> sz = {{0.0, z0}};
  for (const auto& [s0, s1] : notches) {
    sz.insert(sz.end(), {{s0, z0}, {s0, z0 + notch_height}, {s1, z0 + notch_height}, {s1, z0}});
  }
  sz.insert(sz.end(), {{length, z0}, {length, z1}, {0.0, z1}});
  std::vector<Vec3> corners;
  for (const Vec2& p : sz) {
    const Vec2 q = from + p.x() * d;
    corners.emplace_back(q.x(), q.y(), p.y());
  }
  if (!face_right) std::reverse(corners.begin(), corners.end());
  b->Face(corners);
}

// A horizontal face over the counter-clockwise plan ring at height z, facing up or down.
void Horizontal(CaoBuilder* b, const std::vector<Vec2>& ring, double z, bool up) {
  std::vector<Vec3> corners;
  for (const Vec2& p : ring)
    corners.emplace_back(p.x(), p.y(), z);
  if (!up) std::reverse(corners.begin(), corners.end());
  b->Face(corners);
}

// A box [lo, hi] x [z0, z1], faces outward on the sides listed in `sides` ("swne" order of the
// counter-clockwise walk from lo), with its top when `top`.
void Box(CaoBuilder* b, const Vec2& lo, const Vec2& hi, double z0, double z1,
         const std::string& sides, bool top) {
  const std::array<Vec2, 4> c = {lo, Vec2(hi.x(), lo.y()), hi, Vec2(lo.x(), hi.y())};
  const std::string order = "senw";
  for (int i = 0; i < 4; ++i) {
    if (sides.find(order[i]) != std::string::npos) {
      WallFace(b, c[i], c[(i + 1) % 4], z0, z1, {}, 0.0, true);
    }
  }
  if (top) Horizontal(b, {c[0], c[1], c[2], c[3]}, z1, true);
}

void Rectangle(CaoBuilder* b, const std::array<Vec3, 4>& c) {
  for (int i = 0; i < 4; ++i)
    b->Line(c[i], c[(i + 1) % 4]);
}

// A door between a room and the corridor, through the wall between y = ya and y = yb.
struct Door {
  double x0 = 0.0, x1 = 0.0;  // opening along x
  double ya = 0.0, yb = 0.0;  // the wall's two faces (ya < yb)
  bool room_below = true;     // the room lies at y < ya (a south room)
};

struct Layout {
  BuildingSpec spec;
  std::vector<BuildingSpace> spaces;
  std::vector<Door> doors;                      // per room (same index as the room's space)
  std::vector<int> furniture;                   // per room: 0 pillar, 1 cabinet, 2 low box
  double length = 0.0, width = 0.0, top = 0.0;  // outer size of the building (metres)
};

double FloorZ(const BuildingSpec& spec, int storey) {
  return storey * (spec.storey_height + spec.slab);
}

Layout MakeLayout(const BuildingSpec& spec) {
  Layout layout;
  layout.spec = spec;
  const int n = spec.rooms_per_side;
  const double t = spec.wall, depth = spec.room_depth, c = spec.corridor_width;
  double inner = -t;
  for (int i = 0; i < n; ++i)
    inner += kRoomWidths[i % kRoomWidths.size()] + t;
  layout.length = inner + 2.0 * t;
  layout.width = 4.0 * t + 2.0 * depth + c;
  layout.top = FloorZ(spec, spec.storeys - 1) + spec.storey_height;
  const double south_lo = t, corridor_lo = 2.0 * t + depth, north_lo = 3.0 * t + depth + c;
  for (int s = 0; s < spec.storeys; ++s) {
    for (int side = 0; side < 2; ++side) {
      double x = t;
      for (int i = 0; i < n; ++i) {
        const double w = kRoomWidths[(side == 0 ? i : n - 1 - i) % kRoomWidths.size()];
        BuildingSpace room;
        room.name =
            "s" + std::to_string(s) + (side == 0 ? "-south-" : "-north-") + std::to_string(i);
        room.storey = s;
        room.floor_z = FloorZ(spec, s);
        const double y0 = side == 0 ? south_lo : north_lo;
        room.lo = {x, y0};
        room.hi = {x + w, y0 + depth};
        Door door;
        door.x0 = x + 0.4 + 0.6 * ((i + side) % 3);
        door.x1 = door.x0 + spec.door_width;
        door.ya = side == 0 ? south_lo + depth : corridor_lo + c;
        door.yb = door.ya + t;
        door.room_below = side == 0;
        layout.spaces.push_back(room);
        layout.doors.push_back(door);
        layout.furniture.push_back((s * 2 * n + side * n + i) % 3);
        x += w + t;
      }
    }
  }
  for (int s = 0; s < spec.storeys; ++s) {
    BuildingSpace corridor;
    corridor.name = "s" + std::to_string(s) + "-corridor";
    corridor.storey = s;
    corridor.corridor = true;
    corridor.floor_z = FloorZ(spec, s);
    corridor.lo = {t, corridor_lo};
    corridor.hi = {layout.length - t, corridor_lo + c};
    layout.spaces.push_back(corridor);
  }
  return layout;
}

// The reveals of a door: its two jambs and its head; with `leaf_for_room` also a door leaf on
// the wall's far side from the room (for the room alone), or for the corridor alone.
void DoorReveals(CaoBuilder* b, const Door& d, double z0, double height) {
  WallFace(b, {d.x0, d.yb}, {d.x0, d.ya}, z0, z0 + height, {}, 0.0, false);
  WallFace(b, {d.x1, d.ya}, {d.x1, d.yb}, z0, z0 + height, {}, 0.0, false);
  Horizontal(b, {{d.x0, d.ya}, {d.x1, d.ya}, {d.x1, d.yb}, {d.x0, d.yb}}, z0 + height, false);
}

// The casing of a door on the wall face at y: two jambs and a head line around the opening.
void Casing(CaoBuilder* b, const Door& d, double y, double z0, double height) {
  const double x0 = d.x0 - kCasing, x1 = d.x1 + kCasing, top = z0 + height + kCasing;
  b->Line({x0, y, z0}, {x0, y, top});
  b->Line({x0, y, top}, {x1, y, top});
  b->Line({x1, y, top}, {x1, y, z0});
}

void DoorLeaf(CaoBuilder* b, const Door& d, double z0, double height, bool facing_room) {
  // The leaf lies on the face of the wall away from the space it closes, facing that space.
  const bool at_yb = d.room_below == facing_room;
  const double y = at_yb ? d.yb : d.ya;
  const Vec2 from = at_yb ? Vec2(d.x1, y) : Vec2(d.x0, y);
  const Vec2 to = at_yb ? Vec2(d.x0, y) : Vec2(d.x1, y);
  WallFace(b, from, to, z0, z0 + height, {}, 0.0, false);
}

// The floor ring of a room: its rectangle with the threshold of its door.
std::vector<Vec2> RoomFloor(const BuildingSpace& r, const Door& d) {
  if (d.room_below) {
    return {r.lo,
            {r.hi.x(), r.lo.y()},
            r.hi,
            {d.x1, r.hi.y()},
            {d.x1, d.yb},
            {d.x0, d.yb},
            {d.x0, r.hi.y()},
            {r.lo.x(), r.hi.y()}};
  }
  return {r.lo,         {d.x0, r.lo.y()},    {d.x0, d.ya},
          {d.x1, d.ya}, {d.x1, r.lo.y()},    {r.hi.x(), r.lo.y()},
          r.hi,         {r.lo.x(), r.hi.y()}};
}

void AddRoom(CaoBuilder* b, const Layout& layout, int k) {
  const BuildingSpec& spec = layout.spec;
  const BuildingSpace& r = layout.spaces[k];
  const Door& d = layout.doors[k];
  const double z0 = r.floor_z, z1 = z0 + spec.storey_height, w = r.hi.x() - r.lo.x();
  const std::array<Vec2, 4> c = {r.lo, Vec2(r.hi.x(), r.lo.y()), r.hi, Vec2(r.lo.x(), r.hi.y())};
  const std::array<double, 2> south_notch = {d.x0 - r.lo.x(), d.x1 - r.lo.x()};
  const std::array<double, 2> north_notch = {r.hi.x() - d.x1, r.hi.x() - d.x0};
  for (int i = 0; i < 4; ++i) {
    std::vector<std::array<double, 2>> notches;
    if (i == 0 && !d.room_below) notches.push_back(south_notch);
    if (i == 2 && d.room_below) notches.push_back(north_notch);
    WallFace(b, c[i], c[(i + 1) % 4], z0, z1, notches, spec.door_height, false);
  }
  Horizontal(b, RoomFloor(r, d), z0, true);
  Horizontal(b, {c[0], c[1], c[2], c[3]}, z1, false);
  DoorReveals(b, d, z0, spec.door_height);
  // The window on the outer wall, off the cabinet's end.
  const int kind = layout.furniture[k];
  const double outer_y = d.room_below ? r.lo.y() : r.hi.y();
  const double centre = r.lo.x() + (kind == 1 ? 0.68 : 0.5) * w;
  const double half = 0.5 * std::min(kWindowWidth, w - 1.6);
  Rectangle(b, {Vec3(centre - half, outer_y, z0 + kSillHeight),
                Vec3(centre + half, outer_y, z0 + kSillHeight),
                Vec3(centre + half, outer_y, z0 + kWindowHead),
                Vec3(centre - half, outer_y, z0 + kWindowHead)});
  // A radiator under the window, against the outer wall, and the door's casing on the room side.
  const double inner_y = d.room_below ? outer_y + kRadiatorDepth : outer_y - kRadiatorDepth;
  Box(b, {centre - half + 0.1, std::min(outer_y, inner_y)},
      {centre + half - 0.1, std::max(outer_y, inner_y)}, z0, z0 + kRadiatorHeight,
      d.room_below ? "enw" : "sew", true);
  Casing(b, d, d.room_below ? d.ya : d.yb, z0, spec.door_height);
  // A light panel on the ceiling, over the middle of the room.
  const Vec2 mid = 0.5 * (r.lo + r.hi);
  Rectangle(b, {Vec3(mid.x() - kLightSide, mid.y() - 0.5 * kLightSide, z1),
                Vec3(mid.x() + kLightSide, mid.y() - 0.5 * kLightSide, z1),
                Vec3(mid.x() + kLightSide, mid.y() + 0.5 * kLightSide, z1),
                Vec3(mid.x() - kLightSide, mid.y() + 0.5 * kLightSide, z1)});
  const double mid_y = 0.5 * (r.lo.y() + r.hi.y());
  if (kind == 0) {  // a pillar, floor to ceiling
    const Vec2 p(r.lo.x() + 0.62 * w, mid_y - 0.3);
    Box(b, p, p + Vec2(0.4, 0.4), z0, z1, "senw", false);
  } else if (kind == 1) {  // a cabinet against the outer wall, with its top
    const double y_in = d.room_below ? r.lo.y() + 0.5 : r.hi.y() - 0.5;
    const Vec2 lo(r.lo.x() + 0.3, std::min(outer_y, y_in));
    const Vec2 hi(r.lo.x() + 1.5, std::max(outer_y, y_in));
    Box(b, lo, hi, z0, z0 + 1.8, d.room_below ? "enw" : "sew", true);
  } else {  // a low box in the middle of the room
    const Vec2 p(r.lo.x() + 0.45 * w - 0.5, mid_y - 0.3);
    Box(b, p, p + Vec2(1.0, 0.6), z0, z0 + 0.75, "senw", true);
  }
}

void AddCorridor(CaoBuilder* b, const Layout& layout, const BuildingSpace& r) {
  const BuildingSpec& spec = layout.spec;
  const double z0 = r.floor_z, z1 = z0 + spec.storey_height;
  std::vector<std::array<double, 2>> south, north;
  std::vector<Vec2> floor_south, floor_north;
  for (size_t k = 0; k < layout.doors.size(); ++k) {
    if (layout.spaces[k].storey != r.storey) continue;
    const Door& d = layout.doors[k];
    Casing(b, d, d.room_below ? d.yb : d.ya, r.floor_z, spec.door_height);
    if (d.room_below) {
      south.push_back({d.x0 - r.lo.x(), d.x1 - r.lo.x()});
      floor_south.insert(floor_south.end(), {{d.x0, r.lo.y()}, {d.x1, r.lo.y()}});
    } else {
      north.push_back({r.hi.x() - d.x1, r.hi.x() - d.x0});
      floor_north.insert(floor_north.end(), {{d.x1, r.hi.y()}, {d.x0, r.hi.y()}});
    }
  }
  const std::array<Vec2, 4> c = {r.lo, Vec2(r.hi.x(), r.lo.y()), r.hi, Vec2(r.lo.x(), r.hi.y())};
  WallFace(b, c[0], c[1], z0, z1, south, spec.door_height, false);
  WallFace(b, c[1], c[2], z0, z1, {}, 0.0, false);
  WallFace(b, c[2], c[3], z0, z1, north, spec.door_height, false);
  WallFace(b, c[3], c[0], z0, z1, {}, 0.0, false);
  auto by_x = [](const Vec2& a, const Vec2& b2) { return a.x() < b2.x(); };
  std::sort(floor_south.begin(), floor_south.end(), by_x);
  std::sort(floor_north.begin(), floor_north.end(),
            [&](const Vec2& a, const Vec2& b2) { return by_x(b2, a); });
  std::vector<Vec2> ring = {c[0]};
  ring.insert(ring.end(), floor_south.begin(), floor_south.end());
  ring.insert(ring.end(), {c[1], c[2]});
  ring.insert(ring.end(), floor_north.begin(), floor_north.end());
  ring.push_back(c[3]);
  Horizontal(b, ring, z0, true);
  Horizontal(b, {c[0], c[1], c[2], c[3]}, z1, false);
}

}  // namespace

bool BuildingSpec::Check(std::string* why) const {
  if (storeys < 1 || storeys > 10 || rooms_per_side < 1 || rooms_per_side > 100) {
    *why = "storeys must be in [1, 10], rooms_per_side in [1, 100]";
    return false;
  }
  if (!(storey_height >= 2.5 && storey_height <= 10.0 && slab >= 0.05 && slab <= 2.0 &&
        wall >= 0.05 && wall <= 1.0 && room_depth >= 3.0 && room_depth <= 50.0 &&
        corridor_width >= 1.0 && corridor_width <= 20.0)) {
    *why =
        "storey_height in [2.5, 10], slab in [0.05, 2], wall in [0.05, 1], room_depth in "
        "[3, 50], corridor_width in [1, 20] metres";
    return false;
  }
  if (!(door_width >= 0.5 && door_width <= 1.5 && door_height >= 1.8 &&
        door_height < storey_height - 0.1)) {
    *why = "door_width in [0.5, 1.5], door_height in [1.8, storey_height - 0.1) metres";
    return false;
  }
  return true;
}

SyntheticBuilding GenerateBuilding(const BuildingSpec& spec) {
  std::string why;
  if (!spec.Check(&why)) throw InputError("building: " + why);
  const Layout layout = MakeLayout(spec);
  CaoBuilder b;
  const int rooms = static_cast<int>(layout.doors.size());
  for (int k = 0; k < rooms; ++k)
    AddRoom(&b, layout, k);
  for (size_t k = rooms; k < layout.spaces.size(); ++k)
    AddCorridor(&b, layout, layout.spaces[k]);
  // The facade, facing out, floor to roof.
  const std::array<Vec2, 4> c = {Vec2(0, 0), Vec2(layout.length, 0),
                                 Vec2(layout.length, layout.width), Vec2(0, layout.width)};
  for (int i = 0; i < 4; ++i)
    WallFace(&b, c[i], c[(i + 1) % 4], 0.0, layout.top, {}, 0.0, true);
  SyntheticBuilding building;
  building.cao = b.Take("building");
  building.spaces = layout.spaces;
  return building;
}

CaoModel SpaceAlone(const BuildingSpec& spec, int index) {
  std::string why;
  if (!spec.Check(&why)) throw InputError("building: " + why);
  const Layout layout = MakeLayout(spec);
  if (index < 0 || index >= static_cast<int>(layout.spaces.size())) {
    throw InputError("building: no space " + std::to_string(index));
  }
  CaoBuilder b;
  const BuildingSpace& space = layout.spaces[index];
  if (!space.corridor) {
    AddRoom(&b, layout, index);
    DoorLeaf(&b, layout.doors[index], space.floor_z, spec.door_height, true);
  } else {
    AddCorridor(&b, layout, space);
    for (size_t k = 0; k < layout.doors.size(); ++k) {
      if (layout.spaces[k].storey != space.storey) continue;
      DoorReveals(&b, layout.doors[k], space.floor_z, spec.door_height);
      DoorLeaf(&b, layout.doors[k], space.floor_z, spec.door_height, false);
    }
  }
  return b.Take(space.name);
}

}  // namespace linetrack
