// Ray casting against the model's faces, and projection of the visible parts of model edges.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "models/camera.h"
#include "models/geometry.h"
#include "models/wireframe.h"

namespace linetrack {

// Answers "is the segment of sight from A to B blocked by a face?" for one model.
class OcclusionTester {
 public:
  explicit OcclusionTester(const WireframeModel& model);

  // True when a face crosses the open segment from `eye` to `target` (world, metres) before
  // `target`; faces through `target` itself (within `tolerance` metres) do not count.
  bool Blocked(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
               double tolerance = 1e-4) const;
  // The same test against every face in turn, without the plan grid: the reference Blocked must
  // equal.
  bool BlockedByAnyFace(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                        double tolerance = 1e-4) const;

 private:
  struct Face {
    Eigen::Vector3d normal;
    double offset = 0.0;
    int axis_u = 0, axis_v = 1;            // coordinates kept for the 2D inside test
    std::vector<Eigen::Vector2d> polygon;  // face corners in (axis_u, axis_v)
    Eigen::Vector3d box_min, box_max;      // bounding box, for a quick reject
  };
  // A slice of world z, from one storey's slab to the next: the plan grid's cells list only the
  // faces whose z extent meets [z_lo, z_hi].
  struct Layer {
    double z_lo = 0.0, z_hi = 0.0;
    std::vector<std::vector<int>> cells;
  };
  // Fills the plan grid below from the faces' boxes, one layer per storey of `model`.
  void BuildPlanGrid(const WireframeModel& model);
  int Col(double x) const;
  int Row(double y) const;
  // Calls test(face index) for the faces of `layer` whose plan box meets a cell that the plan
  // projection of a -> b passes through, each once, cell by cell from a; stops when test returns
  // true.
  template <typename Test>
  bool AlongPlan(const Layer& layer, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                 const Test& test) const;

  std::vector<Face> faces_;
  // A uniform grid over the faces' plan boxes, per layer: the faces meeting each cell, and per face
  // the rectangle of cells [col_lo, col_hi] x [row_lo, row_hi] it is listed in. The layers cover
  // every z; a face is listed in each layer its z extent meets.
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  double cell_ = 1.0;
  int cols_ = 1, rows_ = 1;
  std::vector<Layer> layers_;
  std::vector<Eigen::Vector4i> rectangles_;
};

// The visible part of one model edge in an image.
struct ProjectedEdge {
  int edge_id = -1;
  Segment2 image;  // undistorted pixels
  Segment3 world;  // the visible part of the edge in the world
};

struct EdgeProjectionOptions {
  double near_clip = 0.05;      // metres in front of the camera
  double sample_step_px = 2.0;  // spacing of the occlusion samples along an edge's image
  double min_length_px = 1.0;   // visible pieces shorter than this are dropped
};

// Projects every model edge seen from `cam_from_world` with `camera` (undistorted model; the
// image size must be known): clipped to the view frustum, split where faces hide it.
std::vector<ProjectedEdge> ProjectVisibleEdges(const WireframeModel& model,
                                               const OcclusionTester& occlusion,
                                               const Eigen::Isometry3d& cam_from_world,
                                               const CameraIntrinsics& camera,
                                               const EdgeProjectionOptions& options = {});

// Clips the world segment to the frustum of `camera` (image rectangle, z > near); false when
// nothing remains. Works in camera coordinates against the five frustum planes.
bool ClipToFrustum(const Eigen::Isometry3d& cam_from_world, const CameraIntrinsics& camera,
                   double near_clip, Segment3* segment);

}  // namespace linetrack
