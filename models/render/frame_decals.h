// Door and window frames: the model's 3D lines that are not face edges (jambs, lintels, sills)
// are painted on the face they lie on as frame bands on the outer side of the opening, and the
// opening itself (door leaf, window pane) is filled, so each line is an intensity step exactly
// where the model puts it.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "models/render/render_scene.h"
#include "models/wireframe.h"

namespace linetrack {

// Connected 3D lines of the model lying on one face.
struct FrameGroup {
  int host_face = -1;
  std::vector<int> edge_ids;
  // The opening: a closed loop of lines (window), or a chain whose two ends stand on the bottom
  // of the host face (door, closed along the floor); empty when the lines enclose nothing.
  std::vector<Eigen::Vector3d> opening;
  bool door = false;
};

// Groups the 3D lines that are not edges of a face by host face and shared vertices. Lines
// lying on no face are counted in *undrawn (may be null).
std::vector<FrameGroup> FindFrameGroups(const WireframeModel& model, int* undrawn);

// Decal surfaces of one group: the opening filled (door leaf or window pane), then one band of
// `width` metres per line on the side away from the opening (centred when there is no side).
// Albedos contrast with the host face's `host_albedo`; `seed` jitters them.
std::vector<RenderSurface> FrameDecals(const WireframeModel& model, const FrameGroup& group,
                                       double host_albedo, double width, uint64_t seed);

// An orthonormal basis (e1, e2) of the plane with unit normal n: e1 horizontal when the plane
// is not, e2 = n x e1 (for a wall: e1 along the wall, e2 vertical).
void PlaneBasis(const Eigen::Vector3d& n, Eigen::Vector3d* e1, Eigen::Vector3d* e2);

// Even-odd test of point p against a planar polygon, both expressed in the basis (e1, e2).
bool InsidePlanarPolygon(const std::vector<Eigen::Vector3d>& polygon, const Eigen::Vector3d& p,
                         const Eigen::Vector3d& e1, const Eigen::Vector3d& e2);

}  // namespace linetrack
