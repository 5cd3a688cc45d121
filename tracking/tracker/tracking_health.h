// Per-frame health of the moving-edge tracker and the checks that decide whether its pose is
// kept: projection error, share of good moving edges, pose covariance, the robot's known height
// and tilt, and the motion between frames. Pure functions: the tests call them directly.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "models/robot_pose.h"

namespace linetrack {

// What one tracked frame measured.
struct TrackHealth {
  // ViSP's projection error (degrees): mean angle between the image gradient and the normal of
  // the projected model edges at sampled points; about 3-15 on a good track, ~50 when wrong.
  double projection_error_deg = 0.0;
  int edges_total = 0;  // moving edges searched in the last pass
  int edges_good = 0;   // of which found and kept by the robust estimator
  // Standard deviations from ViSP's pose covariance (largest axis): translation of cMo (metres)
  // and theta-u rotation (degrees); 0 when not computed (it is, on candidate poses only).
  double position_sigma_m = 0.0;
  double rotation_sigma_deg = 0.0;
  int passes = 0;  // tracking passes run on the frame
  // Sub-pixel refinement: whether it was applied, the edge points it found, and their RMS distance
  // to the model edges before and after (pixels).
  bool refined = false;
  int refined_points = 0;
  std::string refinement_refusal;  // why the refinement was not applied (EdgeRefinement)
  double refined_rms_before_px = 0.0;
  double refined_rms_after_px = 0.0;
  int refined_rejected_edges = 0;  // edges set aside as lying on unmodelled parallel lines
  // With a robot's known height and tilt: standard deviations of the refined position (largest
  // horizontal axis, metres) and heading (degrees); 0 otherwise.
  double refined_position_sigma_m = 0.0;
  double refined_heading_sigma_deg = 0.0;

  double GoodShare() const {
    return edges_total > 0 ? static_cast<double>(edges_good) / edges_total : 0.0;
  }
};

struct HealthThresholds {
  double max_projection_error_deg = 30.0;
  double min_good_share = 0.5;  // edges_good / edges_total
  int min_good_edges = 30;
  double max_position_sigma_m = 0.2;
  double max_rotation_sigma_deg = 3.0;

  bool Check(std::string* why) const;
};

// The camera height, tilt and roll a robot knows (odometry, head encoders, the camera's mount),
// with the tolerances a tracked pose must respect.
struct RobotConstraint {
  double height = 0.0;  // metres
  double tilt = 0.0;    // radians, positive looking down
  double roll = 0.0;    // radians about the optical axis (RobotPose's)
  double height_tolerance = 0.15;
  double tilt_tolerance = 0.0873;  // 5 degrees
  double roll_tolerance = 0.0873;

  bool Check(std::string* why) const;
};

// Largest plausible camera motion between consecutive frames, as speeds.
struct MotionLimits {
  double max_speed = 5.0;          // metres per second (camera centre)
  double max_turn_rate = 6.2832;   // radians per second (rotation angle)
  double min_interval = 1.0 / 60;  // seconds: intervals are taken at least this long

  bool Check(std::string* why) const;
};

// Translation of the camera centre (metres) and rotation angle (radians) between two poses.
struct PoseDifference {
  double translation = 0.0;
  double rotation = 0.0;
};

// Difference between two cam_from_world transforms: |C_a - C_b| with C = -R^T t, and the angle of
// R_a R_b^T.
PoseDifference ComparePoses(const Eigen::Isometry3d& cam_from_world_a,
                            const Eigen::Isometry3d& cam_from_world_b);

// Empty when `health` passes every threshold, else why not ("projection error 41.2 deg > 30").
std::string HealthProblem(const TrackHealth& health, const HealthThresholds& thresholds);

// Empty when the pose respects the robot's height, tilt and roll, else why not.
std::string ConstraintProblem(const Eigen::Isometry3d& cam_from_world,
                              const RobotConstraint& constraint);

// Empty when the move from `previous` to `current` over `interval` seconds is plausible.
std::string MotionProblem(const Eigen::Isometry3d& previous, const Eigen::Isometry3d& current,
                          double interval, const MotionLimits& limits);

// Standard deviations of the largest axes of the translation and rotation blocks of a 6x6
// covariance of (t, theta-u): (metres, radians).
Eigen::Vector2d CovarianceSigmas(const Eigen::Matrix<double, 6, 6>& covariance);

}  // namespace linetrack
