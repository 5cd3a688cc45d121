// Planar helpers shared by the tracking engine's files (sequence_tracker.cc,
// sequence_tracker_recovery.cc): a reading as a robot pose, a camera pose's planar pose, and the
// difference of two planar poses.
#pragma once

#include <Eigen/Geometry>
#include <cmath>

#include "models/robot_pose.h"
#include "tracking/tracker/sequence_tracker.h"

namespace linetrack {

// The robot pose at a planar pose with the reading's height, tilt and roll.
inline RobotPose WithReading(const Pose3Dof& planar, const RobotReading& robot) {
  return RobotPose{planar.x, planar.y, planar.heading, robot.height, robot.tilt, robot.roll};
}

// The planar (x, y, heading) of a camera pose.
inline Pose3Dof PlanarOf(const Eigen::Isometry3d& cam_from_world) {
  return RobotPoseFromCamFromWorld(cam_from_world).Planar();
}

// Position (metres) and heading (radians, wrapped) differences of two planar poses.
inline Eigen::Vector2d PlanarDifference(const Pose3Dof& a, const Pose3Dof& b) {
  return {std::hypot(a.x - b.x, a.y - b.y),
          std::abs(std::remainder(a.heading - b.heading, 2.0 * kPi))};
}

}  // namespace linetrack
