// Robot camera poses in the project's conventions (docs/conventions.md):
// world z up, heading counter-clockwise from +x, tilt positive looking down, ViSP camera axes
// (x right, y down, z forward). A ground robot's camera is level or tilted; a known roll about the
// optical axis (a camera's mount on its head) is carried along, zero by default.
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
// (metres), the tilt of the optical axis below the horizontal (radians, positive down) and the
// roll about the optical axis (radians, positive turning the image's x axis towards its y axis).
struct RobotPose {
  double x = 0.0;
  double y = 0.0;
  double heading = 0.0;
  double height = 0.0;
  double tilt = 0.0;
  double roll = 0.0;

  Pose3Dof Planar() const { return {x, y, heading}; }
  Eigen::Vector3d Centre() const { return {x, y, height}; }
};

// Rotation camera-from-world: rows are the camera axes in world coordinates,
// r = (sin h, -cos h, 0), f = (cos t cos h, cos t sin h, -sin t), d = f x r.
Eigen::Matrix3d CamFromWorldRotation(double heading, double tilt);

// The same camera rolled about its optical axis: Rz(roll)^T CamFromWorldRotation(heading, tilt),
// whose rows are r' = cos(roll) r + sin(roll) d, d' = -sin(roll) r + cos(roll) d and f.
Eigen::Matrix3d CamFromWorldRotation(double heading, double tilt, double roll);

// Rigid transform camera-from-world (ViSP's cMo): X_cam = R (X_world - C), R with the roll.
Eigen::Isometry3d CamFromWorld(const RobotPose& pose);

// Inverse of CamFromWorld (|tilt| < 90 degrees): heading and tilt from the optical axis f,
// roll = atan2(r' . d, r' . r) with r, d the axes of the unrolled camera at that heading and tilt.
RobotPose RobotPoseFromCamFromWorld(const Eigen::Isometry3d& cam_from_world);

// Roll of a camera pose about its optical axis (radians), as RobotPoseFromCamFromWorld reads it.
double RollOf(const Eigen::Isometry3d& cam_from_world);

// Normalised image coordinates (x/z, y/z) of the unrolled camera from those of a camera rolled by
// `roll` about the same optical axis: the 2-D rotation by +roll (x_unrolled = Rz(roll) x_rolled).
Eigen::Vector2d UnrollImagePoint(const Eigen::Vector2d& normalised, double roll);

// Rotation from the tilted camera frame to the level frame (same heading, zero tilt; axes right,
// down, level-forward): v_level = LevelFromCam(tilt) * v_cam.
Eigen::Matrix3d LevelFromCam(double tilt);

}  // namespace linetrack
