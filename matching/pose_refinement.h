// Levenberg-Marquardt estimate of the 3-DOF robot pose (heading, x, y) from line
// correspondences at known height and tilt (paper, section 3.3, after Phong and Horaud 1995).
// Residuals are geometric: the pixel distances of each observed segment's endpoints to the
// projected model line, rather than the paper's algebraic equations (1).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "models/camera.h"
#include "models/geometry.h"
#include "models/robot_pose.h"

namespace linetrack {

// One correspondence for the pose: a model edge (world, metres) and an observed segment
// (undistorted pixels).
struct LineMatch {
  Eigen::Vector3d edge_a, edge_b;
  Segment2 observed;
};

struct PoseRefinementOptions {
  int max_iterations = 15;
  double step_tolerance = 1e-7;  // stop when the update (rad, m) is below this
  double huber_px = 3.0;         // Huber threshold on endpoint residuals (pixels); 0: plain LS
  // Focal scale s (px, py times s) estimated with the pose when > 0: the prior std of s - 1
  // (LineNoise::focal_relative), weighed like one residual of prior_pixel_sigma pixels; only with
  // at least min_matches_for_scale correspondences.
  double focal_prior_sigma = 0.0;
  double prior_pixel_sigma = 3.0;
  int min_matches_for_scale = 5;

  bool Check(std::string* why) const;
};

struct PoseRefinementResult {
  Pose3Dof pose;
  double focal_scale = 1.0;  // estimated scale of px, py (1 when not estimated)
  double rms_px = 0.0;       // RMS endpoint residual at the end
  int iterations = 0;
  bool converged = false;
  // Standard deviations of the pose for 1 pixel of endpoint noise, from (J^T J)^-1: large
  // values mean the correspondences do not pin the pose down (e.g. all lines parallel).
  double position_sigma_m = 0.0;  // largest axis of the position uncertainty (metres)
  double heading_sigma_rad = 0.0;
};

// The two endpoint residuals (pixels, signed) of `match` at `pose`; `jacobian` (optional) gets
// d residual / d (heading, x, y).
Eigen::Vector2d EndpointResiduals(const LineMatch& match, const CameraIntrinsics& camera,
                                  double height, double tilt, const Pose3Dof& pose,
                                  Eigen::Matrix<double, 2, 3>* jacobian = nullptr);

// Refines `start` by Levenberg-Marquardt on all endpoint residuals (Huber-weighted), with the
// focal scale too when the options ask for it (starting from `start_scale`).
PoseRefinementResult RefinePose(const std::vector<LineMatch>& matches,
                                const CameraIntrinsics& camera, double height, double tilt,
                                const Pose3Dof& start, const PoseRefinementOptions& options);
PoseRefinementResult RefinePose(const std::vector<LineMatch>& matches,
                                const CameraIntrinsics& camera, double height, double tilt,
                                const Pose3Dof& start, double start_scale,
                                const PoseRefinementOptions& options);

}  // namespace linetrack
