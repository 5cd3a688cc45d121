#include "models/render/render_scene.h"

#include <algorithm>
#include <cmath>

#include "models/errors.h"
#include "models/render/clutter.h"
#include "models/render/frame_decals.h"
#include "models/render/procedural.h"

namespace linetrack {
namespace {

constexpr double kGoldenFraction = 0.6180339887498949;
constexpr double kLightSpacing = 6.0;       // metres between ceiling lights
constexpr double kLightBelowCeiling = 0.3;  // metres
constexpr double kMinCeilingHeight = 2.0;   // metres, for models without walls above that

// True when every corner lies on one face of the model's bounding box (an outer wall).
bool OnBoundingBox(const ModelFace& face, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  constexpr double kTol = 1e-3;
  for (int axis = 0; axis < 3; ++axis) {
    for (double bound : {lo[axis], hi[axis]}) {
      const bool all =
          std::all_of(face.corners.begin(), face.corners.end(),
                      [&](const Eigen::Vector3d& c) { return std::abs(c[axis] - bound) < kTol; });
      if (all) return true;
    }
  }
  return false;
}

}  // namespace

bool RenderSceneOptions::Check(std::string* why) const {
  if (!(frame_width > 0.0 && frame_width < 1.0)) {
    *why = "frame_width must be in (0, 1) metres";
    return false;
  }
  if (clutter < 0 || clutter > 1000) {
    *why = "clutter must be in [0, 1000]";
    return false;
  }
  if (!(clutter_margin >= 0.0 && clutter_margin < 5.0)) {
    *why = "clutter_margin must be in [0, 5) metres";
    return false;
  }
  for (const RenderSurface& s : extra_surfaces) {
    if (s.polygon.size() < 3 || !(std::abs(s.normal.norm() - 1.0) < 1e-9) ||
        !(s.albedo >= 0.0 && s.albedo <= 1.0)) {
      *why = "an extra surface needs 3 corners, a unit normal and an albedo in [0, 1]";
      return false;
    }
  }
  return true;
}

RenderSurface PlanarSurface(std::vector<Eigen::Vector3d> polygon, SurfaceKind kind, double albedo) {
  RenderSurface s;
  s.kind = kind;
  s.normal = (polygon[1] - polygon[0]).cross(polygon[2] - polygon[0]).normalized();
  s.offset = s.normal.dot(polygon[0]);
  s.polygon = std::move(polygon);
  s.albedo = std::clamp(albedo, 0.0, 1.0);
  return s;
}

double FaceAlbedo(int face, bool outer_wall, uint64_t seed) {
  const double phase = HashUnit(HashCombine(seed, 0xa1bed0ull));
  const double u = std::fmod(phase + face * kGoldenFraction, 1.0);
  return outer_wall ? 0.60 + 0.20 * u : 0.32 + 0.20 * u;
}

RenderScene BuildRenderScene(const WireframeModel& model, const RenderSceneOptions& options,
                             const NavigableArea* free_space) {
  std::string why;
  if (!options.Check(&why)) throw InputError(Located(model.path(), 0, why));
  if (options.clutter > 0 && free_space == nullptr) {
    throw InputError(Located(model.path(), 0, "clutter needs the navigable area of the model"));
  }
  RenderScene scene;
  const Eigen::Vector3d lo = model.BoxMin(), hi = model.BoxMax();
  scene.ceiling_z = std::max(hi.z(), kMinCeilingHeight);
  SeededDraws draws(HashCombine(options.seed, 0x5ce7eull));

  RenderSurface floor;
  floor.kind = SurfaceKind::kFloor;
  floor.albedo = 0.22 + draws.Uniform(-0.03, 0.03);
  RenderSurface ceiling;
  ceiling.kind = SurfaceKind::kCeiling;
  ceiling.offset = scene.ceiling_z;
  ceiling.albedo = 0.88 + draws.Uniform(-0.03, 0.03);
  scene.surfaces = {floor, ceiling};

  std::vector<double> albedo(model.faces().size(), 0.5);
  for (size_t f = 0; f < model.faces().size(); ++f) {
    const ModelFace& face = model.faces()[f];
    if (face.Degenerate()) continue;
    albedo[f] = FaceAlbedo(static_cast<int>(f), OnBoundingBox(face, lo, hi), options.seed);
    RenderSurface s;
    s.kind = SurfaceKind::kModelFace;
    s.polygon = face.corners;
    s.normal = face.normal;
    s.offset = face.offset;
    s.albedo = albedo[f];
    s.model_face = static_cast<int>(f);
    scene.surfaces.push_back(s);
  }
  if (options.clutter > 0) {
    const std::vector<RenderSurface> clutter =
        PlaceClutter(model, *free_space, options.clutter, options.clutter_margin, options.seed,
                     &scene.clutter_placed);
    scene.surfaces.insert(scene.surfaces.end(), clutter.begin(), clutter.end());
  }
  for (const FrameGroup& group : FindFrameGroups(model, &scene.undrawn_lines)) {
    const std::vector<RenderSurface> decals =
        FrameDecals(model, group, albedo[group.host_face], options.frame_width, options.seed);
    scene.surfaces.insert(scene.surfaces.end(), decals.begin(), decals.end());
  }
  scene.surfaces.insert(scene.surfaces.end(), options.extra_surfaces.begin(),
                        options.extra_surfaces.end());

  const int nx = std::max(1, static_cast<int>(std::lround((hi.x() - lo.x()) / kLightSpacing)));
  const int ny = std::max(1, static_cast<int>(std::lround((hi.y() - lo.y()) / kLightSpacing)));
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      scene.lights.emplace_back(lo.x() + (i + 0.5) * (hi.x() - lo.x()) / nx,
                                lo.y() + (j + 0.5) * (hi.y() - lo.y()) / ny,
                                scene.ceiling_z - kLightBelowCeiling);
    }
  }
  return scene;
}

}  // namespace linetrack
