// Sub-pixel refinement of a tracked pose on the image edges. ViSP's moving edges sit on integer
// pixels, which biases the pose by centimetres in deep scenes (docs/tracking.md, the hall). Each
// good moving edge is attached to the projected model edge it lies on, moved to the sub-pixel
// maximum of the image gradient along that edge's normal, and the pose is refined by iteratively
// reweighted Gauss-Newton on the point-to-line distances (Huber weights).
#pragma once

#include <visp3/core/vpImage.h>

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "models/camera.h"
#include "models/geometry.h"

namespace linetrack {

struct EdgeRefinementOptions {
  double association_px = 2.0;     // a site belongs to a projected edge closer than this
  double ambiguity_px = 3.0;       // and no other edge may be closer than this
  double end_margin_px = 4.0;      // sites this close to a projected edge's end are not used
  double search_px = 2.0;          // half length of the sub-pixel search along the normal
  double min_gradient = 3.0;       // grey levels per pixel for an edge point
  double huber_px = 0.5;           // residuals beyond this are down-weighted
  int iterations = 5;              // Gauss-Newton iterations
  int min_points = 20;             // fewer edge points: the pose is left as it is
  double max_correction_px = 3.0;  // a larger mean image motion is refused
  // An edge whose points lie this far from it on average after the solve is set aside (they are
  // on an unmodelled parallel line) and the pose solved again, at most max_edge_rejections times.
  double edge_outlier_px = 1.0;
  int max_edge_rejections = 3;

  bool Check(std::string* why) const;
};

// Sub-pixel offset (pixels along the unit `normal`) of the strongest intensity step within
// +-search_px of `point`: central differences of bilinear samples every half pixel, averaged over
// three parallel lines one pixel apart; the offset is the centroid of the derivative over the
// step around its peak. NaN when the strongest step is weaker than min_gradient (grey levels per
// pixel) or is cut by the window's end.
double SubpixelEdgeOffset(const vpImage<unsigned char>& image, const Eigen::Vector2d& point,
                          const Eigen::Vector2d& normal, double search_px, double min_gradient);

// A robot camera's known height (metres), tilt and roll about the optical axis (radians,
// RobotPose's): with it the refinement estimates x, y and heading only (docs/conventions.md).
struct KnownHeightTilt {
  double height = 0.0;
  double tilt = 0.0;
  double roll = 0.0;  // the mount's, zero for a camera held level
};

// One model edge and the sub-pixel edge points the refinement attached to it: the measurements
// of the pose (tracking/integrity/ computes the pose's covariance and integrity from them).
struct EdgeObservation {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();  // world (metres): the edge's part in view
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector2d> points;  // undistorted pixels
  int model_edge = -1;                  // index of the edge in the refinement's input
  // Unit direction (world), on the face the edge is drawn on and across the edge, in which an
  // unmodelled parallel line may lie beside it (the casing of a door or window frame line) and
  // pull its points; zero when none is expected (tracking/integrity/ widens the edge's error).
  Eigen::Vector3d casing_direction = Eigen::Vector3d::Zero();
};

// The outcome of RefineOnEdges.
struct EdgeRefinement {
  bool applied = false;  // false: too few edge points, no improvement, or a refused correction
  std::string refusal;   // why not applied ("too few points", "no better fit", "correction N px")
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();  // refined (or the start)
  int points = 0;                                                    // edge points used
  double rms_before_px = 0.0;  // point-to-line distances at the start pose
  double rms_after_px = 0.0;   // of the points kept
  int rejected_edges = 0;      // edges set aside (edge_outlier_px) and their points
  int rejected_points = 0;
  // With a known height and tilt: standard deviations of the refined position (largest axis,
  // metres) and heading (radians), from the Gauss-Newton information and the residuals' scale.
  double position_sigma_m = 0.0;
  double heading_sigma_rad = 0.0;
  // When applied: the edges and points of the final solve, and the edges set aside.
  std::vector<EdgeObservation> observations;
  std::vector<EdgeObservation> set_aside;
};

// Where a refinement starts: a pose and, for a robot, its known height, tilt and roll (the result
// then keeps them).
struct RefinementStart {
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();
  std::optional<KnownHeightTilt> known;
};

// Refines start.cam_from_world so that the model `edges` (world) pass through the sub-pixel edge
// points found near `sites` (pixels of the undistorted `image`, e.g. ViSP's good moving edges).
// `camera` is the undistorted camera.
EdgeRefinement RefineOnEdges(const vpImage<unsigned char>& image, const CameraIntrinsics& camera,
                             const std::vector<Segment3>& edges,
                             const std::vector<Eigen::Vector2d>& sites,
                             const RefinementStart& start, const EdgeRefinementOptions& options);

// Coarse alignment of a predicted pose (e.g. from the robot's odometry) before the moving edges
// take over: edge points are searched along the normals of the projected visible model edges,
// first within +-search_px, then within +-solve.search_px, each round followed by the
// Gauss-Newton refinement.
struct EdgeAlignmentOptions {
  double sample_step_px = 6.0;  // distance between searches along a projected edge
  double search_px = 12.0;      // the first search pass: half its length
  int rounds = 2;
  EdgeRefinementOptions solve;  // later rounds search solve.search_px

  bool Check(std::string* why) const;
};

// Aligns start.cam_from_world on the image edges near the projections of `visible` (the visible
// parts of the model edges at that pose, world). `applied` is false when a round finds too few
// points or does not improve.
EdgeRefinement AlignToEdges(const vpImage<unsigned char>& image, const CameraIntrinsics& camera,
                            const std::vector<Segment3>& visible, const RefinementStart& start,
                            const EdgeAlignmentOptions& options);

}  // namespace linetrack
