// The wireframe model linetrack matches against: vertices, straight edges with stable ids, and
// faces (the occluders). Built from a CaoModel.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "models/cao_reader.h"
#include "models/geometry.h"

namespace linetrack {

struct WireframeOptions {
  // An edge is vertical when its angle to the world z axis is below this (degrees).
  double vertical_tolerance_deg = 1.0;
  // Points closer than this (metres) are one vertex; edges are deduplicated on vertices.
  double merge_distance = 1e-6;
  // Turn every face toward the free space it bounds (models/face_orientation.h); false keeps the
  // file's point order.
  bool orient_faces = true;

  bool Check(std::string* why) const;
};

// A model edge. Ids are 0-based and stable: every 3D line of the file in order, then every face
// edge in face order, each distinct edge once.
struct ModelEdge {
  int id = -1;
  int v0 = -1, v1 = -1;  // vertex ids
  Segment3 segment;      // world coordinates
  bool vertical = false;
  bool from_line = false;  // true: a 3D line of the file; false: first seen as a face edge
  int face = -1;           // first face the edge belongs to, -1 for a free 3D line
  // The name="..." of its 3D line; else the names of the named faces it borders, joined by '/'
  // ("wall_south/wall_east"); "" when none is named.
  std::string name;
};

// A planar face (polygon) of the model. The normal follows ViSP's convention: the right-hand rule
// on the vertex order, pointing to the side from which the face is visible; once oriented, toward
// the free space the face bounds.
struct ModelFace {
  std::vector<int> vertices;                         // vertex ids, in file order or reversed
  std::vector<Eigen::Vector3d> corners;              // world coordinates of the vertices
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, zero for a degenerate face
  double offset = 0.0;                               // plane: normal . X = offset
  bool vertical = false;                             // the plane contains the z direction (a wall)
  bool horizontal = false;                           // the plane is z = const (a floor or ceiling)
  bool flipped = false;    // the file's point order was reversed to face the free space
  bool two_sided = false;  // free space on both sides, seen from both
  // Free space in front only (a room's wall, a pillar's side, a facade): no camera sees its back.
  bool one_sided = false;
  std::string name;  // its name="..." in the file ("" without)

  bool Degenerate() const { return normal.isZero(); }
};

// One storey of a building: world heights (metres) of its floor and of the top of its walls.
struct Storey {
  double floor_z = 0.0;
  double top_z = 0.0;
};

class WireframeModel {
 public:
  // Builds the model; throws InputError naming `cao.files.front()` when the options are invalid.
  static WireframeModel FromCao(const CaoModel& cao, const WireframeOptions& options = {});

  // Reads a .cao file and builds its model (throws InputError).
  static WireframeModel Load(const std::string& path, const WireframeOptions& options = {});

  const std::string& path() const { return path_; }
  const std::vector<Eigen::Vector3d>& vertices() const { return vertices_; }
  const std::vector<ModelEdge>& edges() const { return edges_; }
  const std::vector<ModelFace>& faces() const { return faces_; }
  const std::vector<std::string>& warnings() const { return warnings_; }
  // The storeys, lowest first (at least one; see models/free_space.h).
  const std::vector<Storey>& storeys() const { return storeys_; }
  // True when the faces were oriented toward the free space the model encloses (false for an
  // object seen from outside, or with WireframeOptions::orient_faces off).
  bool oriented() const { return oriented_; }
  // What orienting the faces changed, one sentence per kind (empty: nothing).
  const std::vector<std::string>& orientation_summary() const { return orientation_summary_; }
  int num_points() const { return num_points_; }  // points in the file(s), before merging
  int num_lines() const { return num_lines_; }    // 3D lines in the file(s)
  int NumVerticalEdges() const;

  // Axis-aligned bounding box of all vertices (world, metres).
  Eigen::Vector3d BoxMin() const { return box_min_; }
  Eigen::Vector3d BoxMax() const { return box_max_; }

 private:
  std::string path_;
  std::vector<Eigen::Vector3d> vertices_;
  std::vector<ModelEdge> edges_;
  std::vector<ModelFace> faces_;
  std::vector<std::string> warnings_;
  std::vector<Storey> storeys_;
  std::vector<std::string> orientation_summary_;
  bool oriented_ = false;
  int num_points_ = 0;
  int num_lines_ = 0;
  Eigen::Vector3d box_min_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d box_max_ = Eigen::Vector3d::Zero();
};

}  // namespace linetrack
