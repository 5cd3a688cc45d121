// From a triangle mesh (as CAD and BIM exports give it) to the wireframe linetrack needs: welded
// vertices, coplanar triangles merged into polygon faces, collinear vertices removed, feature
// edges kept, tessellation edges and the facets of curved surfaces dropped, thin door and window
// quads near a wall turned into 3D lines on it (docs/models.md, "Bringing your building in").
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "models/cao_reader.h"

namespace linetrack {

// A triangle mesh and line primitives in metres, world frame, z up.
struct ImportMesh {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;  // indices into points
  std::vector<std::array<int, 2>> lines;      // indices into points
};

struct MeshToCaoOptions {
  // Edges where the faces meet at more than this angle (degrees) are feature edges; a planar
  // patch joined to its neighbours across two or more smoother edges is a facet of a curved
  // surface: not a face, only its feature edges are kept (as 3D lines).
  double feature_angle_deg = 30.0;
  // Vertices closer than this are one; a vertex closer than this to the line of its neighbours
  // is dropped (metres).
  double merge_tolerance = 1e-3;
  // Triangles whose normals differ by less than this (degrees), and whose vertices lie within
  // merge_tolerance of one plane, are merged into one face.
  double coplanar_angle_deg = 0.5;
  // An open planar patch (every side a boundary) parallel to a larger face and at most this far
  // in front of it (metres) is a door or a window: its outline becomes 3D lines on that face.
  double opening_distance = 0.05;

  bool Check(std::string* why) const;
};

// What the conversion did, for the summary of `linetrack model-import`.
struct MeshToCaoSummary {
  int input_points = 0, input_triangles = 0, input_lines = 0;
  int welded_points = 0;         // points merged into another within merge_tolerance
  int degenerate_triangles = 0;  // dropped: two corners the same, or no area
  int faces = 0;                 // polygon faces written
  int merged_triangles = 0;      // triangles merged into faces with others
  int collinear_points = 0;      // face and line vertices removed on a straight run
  int tessellation_edges = 0;    // edges between coplanar triangles, dropped
  int feature_edges = 0;         // sharp or boundary edges of the mesh
  int curved_facets = 0;         // planar patches of curved surfaces, dropped as faces
  int openings = 0;              // door and window patches turned into 3D lines
  int holes = 0;                 // holes of faces, kept as 3D lines (.cao faces have none)
  int lines = 0;                 // 3D lines written
};

// The .cao content of `mesh` (faces and 3D lines; points are those used); `summary` (may be null)
// says what was done. Throws InputError naming `source` when the options are invalid or nothing
// of the mesh is left.
CaoModel MeshToCao(const ImportMesh& mesh, const MeshToCaoOptions& options,
                   const std::string& source, MeshToCaoSummary* summary);

// Indices of `points` after welding those within `tolerance` metres (the first of a group is
// kept): map[i] is the kept point for point i.
std::vector<int> WeldPoints(const std::vector<Eigen::Vector3d>& points, double tolerance);

// `loop` (a closed polygon) without the vertices lying within `tolerance` metres of the segment
// joining their neighbours.
std::vector<int> WithoutCollinear(const std::vector<int>& loop,
                                  const std::vector<Eigen::Vector3d>& points, double tolerance);

}  // namespace linetrack
