// Robot camera poses in the project's conventions (docs/conventions.md):
// world z up, heading counter-clockwise from +x, tilt positive looking down, ViSP camera axes
// (x right, y down, z forward), roll zero.
#pragma once

#include <Eigen/Geometry>

namespace linetrack {

// The three unknowns of the localisation problem: camera position on the floor plane (metres)
// and heading (radians, counter-clockwise from world +x).
struct Pose3Dof {
  double x = 0.0;
  double y = 0.0;
  double heading = 0.0;
};

// A full robot camera pose: the 3-DOF pose plus the height of the optical centre above the floor
// (metres) and the tilt of the optical axis below the horizontal (radians, positive down).
struct RobotPose {
  double x = 0.0;
  double y = 0.0;
  double heading = 0.0;
  double height = 0.0;
  double tilt = 0.0;

  Pose3Dof Planar() const { return {x, y, heading}; }
  Eigen::Vector3d Centre() const { return {x, y, height}; }
};

// Rotation camera-from-world: rows are the camera axes in world coordinates,
// r = (sin h, -cos h, 0), f = (cos t cos h, cos t sin h, -sin t), d = f x r.
Eigen::Matrix3d CamFromWorldRotation(double heading, double tilt);

// Rigid transform camera-from-world (ViSP's cMo): X_cam = R (X_world - C).
Eigen::Isometry3d CamFromWorld(const RobotPose& pose);

// Inverse of CamFromWorld for a transform with zero roll; heading and tilt are read from the
// optical axis. Roll is not checked: use RollOf() when that matters.
RobotPose RobotPoseFromCamFromWorld(const Eigen::Isometry3d& cam_from_world);

// Roll of a camera pose (radians): angle of the camera x axis out of the horizontal plane.
double RollOf(const Eigen::Isometry3d& cam_from_world);

// Rotation from the tilted camera frame to the level frame (same heading, zero tilt; axes right,
// down, level-forward): v_level = LevelFromCam(tilt) * v_cam.
Eigen::Matrix3d LevelFromCam(double tilt);

}  // namespace linetrack
