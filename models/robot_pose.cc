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

Eigen::Isometry3d CamFromWorld(const RobotPose& pose) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = CamFromWorldRotation(pose.heading, pose.tilt);
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
  pose.heading = std::atan2(right.x(), -right.y());
  pose.tilt = std::asin(std::clamp(-forward.z(), -1.0, 1.0));
  return pose;
}

double RollOf(const Eigen::Isometry3d& cam_from_world) {
  return std::asin(std::clamp(cam_from_world.linear()(0, 2), -1.0, 1.0));
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
