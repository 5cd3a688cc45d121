#include "models/robot_pose.h"

#include <algorithm>
#include <cmath>

namespace linetrack {

Eigen::Matrix3d CamFromWorldRotation(double heading, double tilt) {
  const double ch = std::cos(heading), sh = std::sin(heading);
  const double ct = std::cos(tilt), st = std::sin(tilt);
  const Eigen::Vector3d right(sh, -ch, 0.0);
  const Eigen::Vector3d forward(ct * ch, ct * sh, -st);
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d r;
  r.row(0) = right.transpose();
  r.row(1) = down.transpose();
  r.row(2) = forward.transpose();
  return r;
}

Eigen::Matrix3d CamFromWorldRotation(double heading, double tilt, double roll) {
  const Eigen::Matrix3d level = CamFromWorldRotation(heading, tilt);
  if (roll == 0.0) return level;
  const double c = std::cos(roll), s = std::sin(roll);
  Eigen::Matrix3d r;
  r.row(0) = c * level.row(0) + s * level.row(1);
  r.row(1) = -s * level.row(0) + c * level.row(1);
  r.row(2) = level.row(2);
  return r;
}

Eigen::Isometry3d CamFromWorld(const RobotPose& pose) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = CamFromWorldRotation(pose.heading, pose.tilt, pose.roll);
  t.translation() = -t.linear() * pose.Centre();
  return t;
}

RobotPose RobotPoseFromCamFromWorld(const Eigen::Isometry3d& cam_from_world) {
  const Eigen::Matrix3d r = cam_from_world.linear();
  const Eigen::Vector3d right = r.row(0).transpose();
  const Eigen::Vector3d forward = r.row(2).transpose();
  const Eigen::Vector3d centre = -r.transpose() * cam_from_world.translation();
  RobotPose pose;
  pose.x = centre.x();
  pose.y = centre.y();
  pose.height = centre.z();
  // The heading of f itself: for a camera without roll it equals atan2(r_x, -r_y).
  pose.heading = std::atan2(forward.y(), forward.x());
  pose.tilt = std::asin(std::clamp(-forward.z(), -1.0, 1.0));
  const Eigen::Matrix3d level = CamFromWorldRotation(pose.heading, pose.tilt);
  pose.roll = std::atan2(right.dot(level.row(1)), right.dot(level.row(0)));
  return pose;
}

double RollOf(const Eigen::Isometry3d& cam_from_world) {
  return RobotPoseFromCamFromWorld(cam_from_world).roll;
}

Eigen::Vector2d UnrollImagePoint(const Eigen::Vector2d& normalised, double roll) {
  const double c = std::cos(roll), s = std::sin(roll);
  return {c * normalised.x() - s * normalised.y(), s * normalised.x() + c * normalised.y()};
}

Eigen::Matrix3d LevelFromCam(double tilt) {
  const double ct = std::cos(tilt), st = std::sin(tilt);
  Eigen::Matrix3d m;
  m << 1.0, 0.0, 0.0,  //
      0.0, ct, st,     //
      0.0, -st, ct;
  return m;
}

}  // namespace linetrack
