#include "models/render/people.h"

#include <algorithm>
#include <cmath>

#include "models/render/procedural.h"

namespace linetrack {
namespace {

constexpr double kLegsTop = 0.48;        // share of the height
constexpr double kTorsoTop = 0.86;       // share of the height
constexpr double kLegsWidth = 0.36;      // metres across the walk
constexpr double kTorsoWidth = 0.46;     // metres across the walk
constexpr double kHeadWidth = 0.20;      // metres
constexpr double kBodyDepth = 0.26;      // metres along the walk
constexpr double kStripe = 0.07;         // metres: height of a shirt stripe
constexpr double kClothesTexture = 4.0;  // texture gain of clothes (20 % contrast)

RenderSurface Face(std::vector<Eigen::Vector3d> polygon, double albedo) {
  RenderSurface s = PlanarSurface(std::move(polygon), SurfaceKind::kPerson, albedo);
  s.texture_gain = kClothesTexture;
  return s;
}

// The faces of a box centred on `centre` (floor point) with axes f (forward) and l (left):
// depth along f, width along l, from z0 to z1; the top when `top`.
void AddBox(const Eigen::Vector2d& centre, const Eigen::Vector2d& f, const Eigen::Vector2d& l,
            double depth, double width, double z0, double z1, bool top, double albedo,
            std::vector<RenderSurface>* out) {
  std::vector<Eigen::Vector2d> corners;
  for (const auto& [a, b] :
       {std::pair{1, 1}, std::pair{-1, 1}, std::pair{-1, -1}, std::pair{1, -1}}) {
    corners.push_back(centre + 0.5 * depth * a * f + 0.5 * width * b * l);
  }
  for (size_t k = 0; k < 4; ++k) {
    const Eigen::Vector2d& p = corners[k];
    const Eigen::Vector2d& q = corners[(k + 1) % 4];
    out->push_back(Face(
        {{p.x(), p.y(), z0}, {q.x(), q.y(), z0}, {q.x(), q.y(), z1}, {p.x(), p.y(), z1}}, albedo));
  }
  if (top) {
    std::vector<Eigen::Vector3d> lid;
    for (const Eigen::Vector2d& c : corners)
      lid.emplace_back(c.x(), c.y(), z1);
    out->push_back(Face(lid, albedo));
  }
}

// Horizontal stripes painted on the torso's four sides (decals on each side's plane).
void AddStripes(const std::vector<RenderSurface>& torso_sides, double z0, double z1, double albedo,
                std::vector<RenderSurface>* out) {
  for (const RenderSurface& side : torso_sides) {
    const Eigen::Vector3d a = side.polygon[0], b = side.polygon[1];  // bottom corners
    for (double z = z0 + kStripe; z + kStripe <= z1; z += 2.0 * kStripe) {
      RenderSurface stripe = side;
      stripe.polygon = {{a.x(), a.y(), z},
                        {b.x(), b.y(), z},
                        {b.x(), b.y(), z + kStripe},
                        {a.x(), a.y(), z + kStripe}};
      stripe.albedo = albedo;
      stripe.decal = true;
      out->push_back(stripe);
    }
  }
}

}  // namespace

std::vector<RenderSurface> PersonSurfaces(const PersonWalk& walk, double t) {
  std::vector<RenderSurface> out;
  if (!walk.InSceneAt(t) || !(walk.velocity.norm() > 0.0)) return out;
  SeededDraws draws(HashCombine(walk.look, 0x9e0b1eull));
  const double trousers = draws.Uniform(0.06, 0.30);
  const double shirt = draws.Uniform(0.25, 0.85);
  const double stripes =
      shirt > 0.55 ? shirt - draws.Uniform(0.25, 0.45) : shirt + draws.Uniform(0.25, 0.45);
  const double skin = draws.Uniform(0.35, 0.70);

  const Eigen::Vector2d f = walk.velocity.normalized();
  const Eigen::Vector2d l(-f.y(), f.x());
  const Eigen::Vector2d c = walk.PositionAt(t);
  const double h = walk.height;
  AddBox(c, f, l, kBodyDepth * 0.8, kLegsWidth, 0.0, kLegsTop * h, false, trousers, &out);
  const size_t torso = out.size();
  AddBox(c, f, l, kBodyDepth, kTorsoWidth, kLegsTop * h, kTorsoTop * h, true, shirt, &out);
  const std::vector<RenderSurface> sides(out.begin() + torso, out.begin() + torso + 4);
  AddBox(c, f, l, kHeadWidth * 1.1, kHeadWidth, kTorsoTop * h + 0.02, h, true, skin, &out);
  AddStripes(sides, kLegsTop * h, kTorsoTop * h, stripes, &out);
  return out;
}

}  // namespace linetrack
