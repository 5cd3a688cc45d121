#include "tracking/tracker/tracking_health.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>

#include "models/geometry.h"

namespace linetrack {

namespace {

std::string Format(const char* format, double a, double b) {
  char text[160];
  std::snprintf(text, sizeof(text), format, a, b);
  return text;
}

}  // namespace

bool HealthThresholds::Check(std::string* why) const {
  if (!(max_projection_error_deg > 0.0 && max_projection_error_deg <= 90.0)) {
    *why = "max projection error must be in (0, 90] degrees";
    return false;
  }
  if (!(min_good_share >= 0.0 && min_good_share <= 1.0) || min_good_edges < 0) {
    *why = "min good share must be in [0, 1] and min good edges >= 0";
    return false;
  }
  if (!(max_position_sigma_m > 0.0) || !(max_rotation_sigma_deg > 0.0)) {
    *why = "covariance limits must be positive";
    return false;
  }
  return true;
}

bool RobotConstraint::Check(std::string* why) const {
  if (!std::isfinite(height) || !(std::abs(tilt) < M_PI / 2) || !std::isfinite(roll)) {
    *why = "robot height and roll must be finite and tilt within (-90, 90) degrees";
    return false;
  }
  if (!(height_tolerance > 0.0) || !(tilt_tolerance > 0.0) || !(roll_tolerance > 0.0)) {
    *why = "robot constraint tolerances must be positive";
    return false;
  }
  return true;
}

bool MotionLimits::Check(std::string* why) const {
  if (!(max_speed > 0.0) || !(max_turn_rate > 0.0) || !(min_interval > 0.0)) {
    *why = "motion limits must be positive";
    return false;
  }
  return true;
}

PoseDifference ComparePoses(const Eigen::Isometry3d& cam_from_world_a,
                            const Eigen::Isometry3d& cam_from_world_b) {
  const Eigen::Vector3d centre_a =
      -cam_from_world_a.linear().transpose() * cam_from_world_a.translation();
  const Eigen::Vector3d centre_b =
      -cam_from_world_b.linear().transpose() * cam_from_world_b.translation();
  const Eigen::Matrix3d relative =
      cam_from_world_a.linear() * cam_from_world_b.linear().transpose();
  return {(centre_a - centre_b).norm(), Eigen::AngleAxisd(relative).angle()};
}

std::string HealthProblem(const TrackHealth& health, const HealthThresholds& thresholds) {
  if (!(health.projection_error_deg <= thresholds.max_projection_error_deg)) {
    return Format("projection error %.1f deg > %.1f", health.projection_error_deg,
                  thresholds.max_projection_error_deg);
  }
  if (health.edges_good < thresholds.min_good_edges) {
    return Format("%.0f good moving edges < %.0f", health.edges_good, thresholds.min_good_edges);
  }
  if (!(health.GoodShare() >= thresholds.min_good_share)) {
    return Format("good moving edges %.2f < %.2f", health.GoodShare(), thresholds.min_good_share);
  }
  if (!(health.position_sigma_m <= thresholds.max_position_sigma_m)) {
    return Format("position sigma %.3f m > %.3f", health.position_sigma_m,
                  thresholds.max_position_sigma_m);
  }
  if (!(health.rotation_sigma_deg <= thresholds.max_rotation_sigma_deg)) {
    return Format("rotation sigma %.2f deg > %.2f", health.rotation_sigma_deg,
                  thresholds.max_rotation_sigma_deg);
  }
  return {};
}

std::string ConstraintProblem(const Eigen::Isometry3d& cam_from_world,
                              const RobotConstraint& constraint) {
  const RobotPose pose = RobotPoseFromCamFromWorld(cam_from_world);
  if (!(std::abs(pose.height - constraint.height) <= constraint.height_tolerance)) {
    return Format("camera height %.2f m, the robot says %.2f", pose.height, constraint.height);
  }
  if (!(std::abs(pose.tilt - constraint.tilt) <= constraint.tilt_tolerance)) {
    return Format("tilt %.1f deg, the robot says %.1f", RadToDeg(pose.tilt),
                  RadToDeg(constraint.tilt));
  }
  if (!(std::abs(WrapAngle(pose.roll - constraint.roll)) <= constraint.roll_tolerance)) {
    return Format("roll %.1f deg, the robot says %.1f", RadToDeg(pose.roll),
                  RadToDeg(constraint.roll));
  }
  return {};
}

std::string MotionProblem(const Eigen::Isometry3d& previous, const Eigen::Isometry3d& current,
                          double interval, const MotionLimits& limits) {
  const double dt = std::max(interval, limits.min_interval);
  const PoseDifference move = ComparePoses(current, previous);
  if (!(move.translation <= limits.max_speed * dt)) {
    return Format("camera jumped %.2f m in %.3f s", move.translation, dt);
  }
  if (!(move.rotation <= limits.max_turn_rate * dt)) {
    return Format("camera turned %.1f deg in %.3f s", RadToDeg(move.rotation), dt);
  }
  return {};
}

Eigen::Vector2d CovarianceSigmas(const Eigen::Matrix<double, 6, 6>& covariance) {
  const Eigen::Matrix3d position = covariance.topLeftCorner<3, 3>();
  const Eigen::Matrix3d rotation = covariance.bottomRightCorner<3, 3>();
  const double position_var =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(position, Eigen::EigenvaluesOnly)
          .eigenvalues()
          .maxCoeff();
  const double rotation_var =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(rotation, Eigen::EigenvaluesOnly)
          .eigenvalues()
          .maxCoeff();
  return {std::sqrt(std::max(0.0, position_var)), std::sqrt(std::max(0.0, rotation_var))};
}

}  // namespace linetrack
