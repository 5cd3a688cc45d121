// Where a camera on a pan-tilt head looks from a robot base in the world, and the head angles that
// look at a world point. Frames: the head's base frame has its origin where the pan and tilt axes
// cross, x forward along the robot's heading, z up (head_kinematics.h); the camera pose on it is
// BaseFromCamera(geometry, pan, tilt). Conventions of docs/conventions.md.
#pragma once

#include <Eigen/Geometry>

#include "models/robot_pose.h"
#include "tracking/head/head_kinematics.h"

namespace linetrack {

// The head's base in the world: origin (x, y, crossing_height), rotated by the base heading about
// z. `base` is the robot base's planar pose (its heading, not the camera's).
Eigen::Isometry3d WorldFromHeadBase(const Pose3Dof& base, double crossing_height);

// Height of the axes' crossing that puts the camera centre `camera_height` above the floor when the
// head is level (the camera centre rises by offset_z cos(tilt) + offset_x sin(tilt) above it).
double CrossingHeightFor(const HeadGeometry& geometry, double camera_height);

// cam_from_world of the camera on the head: (WorldFromHeadBase(base) BaseFromCamera(pan, tilt))^-1.
Eigen::Isometry3d CamFromWorldOnHead(const HeadGeometry& geometry, const Pose3Dof& base,
                                     double crossing_height, double pan, double tilt);

// The camera's pose in the matcher's terms: its centre (x, y, height) on the head, heading = base
// heading + pan, tilt = head tilt (the paper's "tilt known but variable" case).
RobotPose CameraPoseOnHead(const HeadGeometry& geometry, const Pose3Dof& base,
                           double crossing_height, double pan, double tilt);

// Head angles that put the world point `target` on the optical axis (the image centre), pan in
// (-pi, pi]. With the target p' in the panned frame: p'_y = offset_y fixes the pan,
// p'_x sin(tilt) + p'_z cos(tilt) = offset_z the tilt; the solution keeps the target in front.
// False when the target is too close to the axes for the camera offset (or offset_x != 0).
bool HeadAnglesLookingAt(const HeadGeometry& geometry, const Eigen::Isometry3d& world_from_base,
                         const Eigen::Vector3d& target, double* pan, double* tilt);

}  // namespace linetrack
