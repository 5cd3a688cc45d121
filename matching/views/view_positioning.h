// Positioning from two stored views where no 3D model exists (seed 002, sections 3.1-3.2): the
// best retrieved key view and a second one with a known relative pose, the junctions seen in
// both and in the image, the linear combination of views (eq. 4) fitted robustly, and the
// camera's pose from its coefficients (eqs. 9-13), with the check of the weak-perspective
// approximation (eqs. 10 and 11 must give one scale, the recovered rows must be orthogonal).
// docs/views.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "matching/views/retrieval.h"
#include "matching/views/view_combination.h"
#include "models/robot_pose.h"

namespace linetrack {

struct ViewPositioningOptions {
  RetrievalOptions retrieval;
  int merged_views = 3;  // retrieved views whose pairs give the image's line ids
  // Between the two model views: a heading change (eq. 4's basis needs a rotation about the
  // vertical) and a baseline (the reference depth is unobservable from a pure rotation).
  double min_heading_change_deg = 10.0;
  double min_baseline_m = 0.5;
  double max_baseline_m = 3.0;           // farther views see the scene too differently
  double min_junction_angle_deg = 15.0;  // image lines meeting at a narrower angle give no point
  // Junctions seen in the three views: four determine eq. 4 exactly (then only the
  // weak-perspective check tests them); with more, RANSAC.
  int min_points = 4;
  double inlier_px = 5.0;  // RANSAC threshold on the combination's residual
  int ransac_iterations = 300;
  uint64_t seed = 1;
  // The weak-perspective check: |s_a - s_b| / s_n and |U_1 . U_2| at most these.
  double max_scale_mismatch = 0.1;
  double max_orthogonality = 0.1;
  // The robot's camera: zero roll, and the height and tilt of the model view (the database's
  // views share the robot's). A pose beyond these is implausible.
  double max_roll_deg = 3.0;
  double max_tilt_change_deg = 5.0;
  double max_height_change_m = 0.5;

  bool Check(std::string* why) const;
};

struct ViewPositioning {
  bool found = false;
  std::string reason;          // why not, when !found
  RobotPose pose;              // world; height and tilt as recovered
  double roll = 0.0;           // radians, recovered (0 for the truth)
  int view1 = -1, view2 = -1;  // the model views (indices into the database)
  int points = 0, inliers = 0;
  double reference_depth = 0.0;  // Z0, metres
  double scale_a = 0.0, scale_b = 0.0, orthogonality = 0.0;
  double rms_px = 0.0;               // residual of the combination on the inliers (pixels)
  bool weak_perspective_ok = false;  // the check of eqs. 10-11 and orthogonality passed
  bool plausible = false;            // roll, tilt and height within the options' bounds

  bool Valid() const { return found && weak_perspective_ok && plausible; }
};

// The camera pose of an image's undistorted segments from the database's key views. Throws
// InputError when the options are invalid.
ViewPositioning LocalizeFromViews(const std::vector<Segment2>& lines, const ViewDatabase& db,
                                  const ViewPositioningOptions& options);

// The intersection (pixels) of the two segments' lines, nullopt when they meet at less than
// `min_angle` radians.
std::optional<Eigen::Vector2d> LineIntersection(const Segment2& a, const Segment2& b,
                                                double min_angle);

}  // namespace linetrack
