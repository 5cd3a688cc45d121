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
// (undistorted pixels). `whitening` W maps the two endpoint residuals to independent unit
// variables (W^T W is the inverse of their covariance, pixels^-2); the identity means
// independent 1-pixel noise.
struct LineMatch {
  Eigen::Vector3d edge_a, edge_b;
  Segment2 observed;
  Eigen::Matrix2d whitening = Eigen::Matrix2d::Identity();
};

// The region a refined pose may not leave (the prior: a hypothesis' pairs alone may pull the pose
// along a weakly observed direction far out of it): the disk of radius radius_m + sigmas *
// position sigma around centre, and headings within half_width_rad
// + sigmas * heading sigma of `heading`, the sigmas those of the image evidence at the pose
// (PoseRefinementResult::position_sigma_m, heading_sigma_rad; RefinePose takes them at each step's
// iterate and holds them during the step's trials). Outside it the cost gains the
// one-sided residuals (d - R)_+ / softness_m and (|heading offset| - H)_+ / softness_rad: zero
// inside, so a pose whose optimum lies inside is unchanged, and one that would slide out stops at
// the border (within about softness^2 times the image cost's gradient).
struct PoseBounds {
  bool active = false;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius_m = 0.0;
  double heading = 0.0;  // middle of the heading interval (rad)
  double half_width_rad = 0.0;
  double sigmas = 0.0;
  double softness_m = 1e-4;
  double softness_rad = 1e-5;
};

// The two one-sided residuals of `bounds` at `pose` for the border radius_m (metres) and
// half_width_rad (already widened by the pose's sigmas): ((d - radius_m)_+ / softness_m,
// (|offset| - half_width_rad)_+ / softness_rad); `jacobian` (optional) gets d residual /
// d (heading, x, y), the widening held fixed.
Eigen::Vector2d BoundsResiduals(const PoseBounds& bounds, const Pose3Dof& pose, double radius_m,
                                double half_width_rad,
                                Eigen::Matrix<double, 2, 3>* jacobian = nullptr);

struct PoseRefinementOptions {
  int max_iterations = 15;
  double step_tolerance = 1e-7;  // stop when the update (rad, m) is below this
  double huber_px = 3.0;         // Huber threshold on whitened residuals; 0: plain least squares
  // Focal scale s (px, py times s) estimated with the pose when > 0: MAP with the prior
  // s ~ N(1, focal_prior_sigma) (LineNoise::focal_relative), with at least
  // min_matches_for_scale correspondences.
  double focal_prior_sigma = 0.0;
  int min_matches_for_scale = 2;
  PoseBounds bounds;  // inactive by default

  bool Check(std::string* why) const;
};

struct PoseRefinementResult {
  Pose3Dof pose;
  double focal_scale = 1.0;  // estimated scale of px, py (1 when not estimated)
  double rms_px = 0.0;       // RMS endpoint residual at the end (pixels, not whitened)
  double chi2 = 0.0;         // sum of the squared whitened residuals at the end
  int iterations = 0;
  bool converged = false;
  // Covariance of (heading, x, y, focal scale) from the inverse of the Gauss-Newton information
  // (whitened residuals and the scale prior); the scale row and column are zero when it is not
  // estimated. With identity whitening it is the covariance for 1 pixel of endpoint noise.
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  // Derived from `covariance`: largest axis of the position uncertainty (metres) and the heading
  // standard deviation; infinite when the correspondences do not pin the pose down.
  double position_sigma_m = 0.0;
  double heading_sigma_rad = 0.0;
  // With active bounds: how far the final pose lies outside them (metres, radians; 0 inside),
  // and the covariance of the cost actually minimised (the image information plus the bounds'
  // residuals', Gauss-Newton), the one the leave-one-out poses (DeletedPose, OutlyingPair) need.
  // Equal to `covariance` when the pose is inside the bounds.
  double bounds_excess_m = 0.0;
  double bounds_excess_rad = 0.0;
  Eigen::Matrix4d bounded_covariance = Eigen::Matrix4d::Zero();
  // True when the bounds held the pose: it ended outside them by a hair, or inside but with the
  // image evidence's Gauss-Newton step leading out of them.
  bool held_by_bounds = false;
};

// The camera-from-world rotation of a robot pose, its derivative w.r.t. the heading and the
// camera centre: computed once for many projections at one pose.
struct PoseView {
  Eigen::Matrix3d rotation;
  Eigen::Matrix3d d_rotation;
  Eigen::Vector3d centre;
};
PoseView ViewOf(const Pose3Dof& pose, double height, double tilt);

// A 3-DOF pose with the focal scale of the camera that sees it: px and py times focal_scale (the
// calibration error estimated with the pose).
struct PoseAndScale {
  Pose3Dof pose;
  double focal_scale = 1.0;
};

// The image line of the model edge through a and b (world) seen from `view` with the focal
// lengths scaled by `scale`: (l_u, l_v, l_c) with l_u u + l_v v + l_c = 0 and l_u^2 + l_v^2 = 1
// (pixels; the line through the projections of a and b). `derivative` (optional) gets
// d line / d (heading, x, y, scale).
Eigen::Vector3d ProjectedEdgeLine(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const CameraIntrinsics& camera, const PoseView& view,
                                  double scale, Eigen::Matrix<double, 3, 4>* derivative);

// The two endpoint residuals (pixels, signed) of `match` at `pose`; `jacobian` (optional) gets
// d residual / d (heading, x, y).
Eigen::Vector2d EndpointResiduals(const LineMatch& match, const CameraIntrinsics& camera,
                                  double height, double tilt, const Pose3Dof& pose,
                                  Eigen::Matrix<double, 2, 3>* jacobian = nullptr);

// The same with the focal lengths scaled by pose.focal_scale; `jacobian` (optional) gets
// d residual / d (heading, x, y, scale).
Eigen::Vector2d EndpointResiduals(const LineMatch& match, const CameraIntrinsics& camera,
                                  double height, double tilt, const PoseAndScale& pose,
                                  Eigen::Matrix<double, 2, 4>* jacobian);
Eigen::Vector2d EndpointResiduals(const LineMatch& match, const CameraIntrinsics& camera,
                                  const PoseView& view, double scale,
                                  Eigen::Matrix<double, 2, 4>* jacobian);

// The largest position standard deviation (metres) of a position covariance (x, y): the square
// root of its largest eigenvalue (0 when that is negative by rounding).
double LargestPositionSigma(const Eigen::Matrix2d& position_covariance);

// Refines `start` by Levenberg-Marquardt on all whitened endpoint residuals (Huber-weighted),
// with the focal scale too when the options ask for it (starting from start.focal_scale), and
// the residuals of options.bounds when active (steps in pose_refinement_steps.h).
PoseRefinementResult RefinePose(const std::vector<LineMatch>& matches,
                                const CameraIntrinsics& camera, double height, double tilt,
                                const PoseAndScale& start, const PoseRefinementOptions& options);
// The same from focal scale 1.
PoseRefinementResult RefinePose(const std::vector<LineMatch>& matches,
                                const CameraIntrinsics& camera, double height, double tilt,
                                const Pose3Dof& start, const PoseRefinementOptions& options);

}  // namespace linetrack
