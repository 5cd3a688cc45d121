// What the renderer draws, in world coordinates: the model's faces with their albedos, the
// implicit floor (z = 0) and ceiling (z = model top) planes, door and window frames painted on
// the walls, optional unmodelled clutter, and the ceiling lights. Independent of any camera.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "models/navigable_area.h"
#include "models/wireframe.h"

namespace linetrack {

enum class SurfaceKind {
  kFloor,       // implicit infinite plane z = 0
  kCeiling,     // implicit infinite plane z = model top
  kModelFace,   // a face of the .cao model
  kFrameTrim,   // a door or window frame band painted along a 3D line of the model
  kDoorLeaf,    // the region inside a jamb-lintel-jamb chain
  kWindowPane,  // the region inside a closed loop of lines
  kClutter,     // unmodelled objects: boxes, cabinets, posters
  kPerson,      // people walking through the scene (moving occluders)
  kBoard,       // a calibration board and its squares (board_surfaces.h)
};

// One planar surface. Decals are painted onto the coplanar surface already visible (same plane,
// same depth) and never occlude; other surfaces are solid, visible from both sides.
struct RenderSurface {
  SurfaceKind kind = SurfaceKind::kModelFace;
  std::vector<Eigen::Vector3d> polygon;  // world corners; empty for the floor and ceiling
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit; plane normal . X = offset
  double offset = 0.0;
  double albedo = 0.5;  // reflectance in [0, 1]
  bool decal = false;
  int model_face = -1;        // index into WireframeModel::faces() (kModelFace, and a decal's host)
  double texture_gain = 1.0;  // multiplies the renderer's texture contrast on this surface
};

struct RenderSceneOptions {
  uint64_t seed = 1;             // albedos, texture and clutter placement
  double frame_width = 0.07;     // width of door and window frame bands (metres)
  int clutter = 0;               // number of unmodelled objects to place
  double clutter_margin = 0.15;  // free space kept around doors, windows and other clutter (m)
  // Surfaces added as given after the model's: a calibration board (board_surfaces.h).
  std::vector<RenderSurface> extra_surfaces;

  bool Check(std::string* why) const;
};

struct RenderScene {
  std::vector<RenderSurface> surfaces;  // index = surface id; 0 floor, 1 ceiling
  std::vector<Eigen::Vector3d> lights;  // point lights below the ceiling (world)
  double ceiling_z = 0.0;
  int undrawn_lines = 0;   // 3D lines that lie on no face (not drawn)
  int clutter_placed = 0;  // may be fewer than asked when the walls have no room left
};

// Surface ids of the implicit planes.
constexpr int kFloorSurface = 0;
constexpr int kCeilingSurface = 1;

// Builds the scene of `model`. `free_space` tells on which side of a wall the room is and is
// needed only for clutter (throws InputError naming the model when clutter is asked without it).
RenderScene BuildRenderScene(const WireframeModel& model, const RenderSceneOptions& options,
                             const NavigableArea* free_space = nullptr);

// A solid surface of `kind` on the plane of `polygon` (its normal by the right-hand rule on the
// first three corners, which must not be collinear), the albedo clamped to [0, 1].
RenderSurface PlanarSurface(std::vector<Eigen::Vector3d> polygon, SurfaceKind kind, double albedo);

// Albedo of model face `face` for `seed`: faces on the model's bounding box (outer walls) in
// [0.60, 0.80], inner faces (pillars, partitions) in [0.32, 0.52], consecutive indices apart by
// the golden-ratio sequence so that neighbouring faces differ.
double FaceAlbedo(int face, bool outer_wall, uint64_t seed);

}  // namespace linetrack
