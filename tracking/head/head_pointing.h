// Where a camera on a pan-tilt head looks from a robot base in the world, and the head angles that
// look at a world point. Frames: the head's base frame has its origin where the pan and tilt axes
// cross, x forward along the robot's heading, z up when the base is level (head_kinematics.h);
// the camera pose on it is BaseFromCamera(geometry, pan, tilt). Conventions of
// docs/conventions.md.
#pragma once

#include <Eigen/Geometry>

#include "models/robot_pose.h"
#include "tracking/head/head_kinematics.h"

namespace linetrack {

// The head's base in the world: origin (x, y, crossing_height), rotated by the base heading about
// z, then tilted by geometry.level_from_base. `base` is the robot base's planar pose (its heading,
// not the camera's).
Eigen::Isometry3d WorldFromHeadBase(const HeadGeometry& geometry, const Pose3Dof& base,
                                    double crossing_height);

// Height of the axes' crossing that puts the camera centre `camera_height` above the floor when the
// head is level (pan and tilt zero): camera_height - (level_from_base t).z, t the camera centre in
// the tilt frame.
double CrossingHeightFor(const HeadGeometry& geometry, double camera_height);

// cam_from_world of the camera on the head: (WorldFromHeadBase(base) BaseFromCamera(pan, tilt))^-1.
Eigen::Isometry3d CamFromWorldOnHead(const HeadGeometry& geometry, const Pose3Dof& base,
                                     double crossing_height, double pan, double tilt);

// The camera's pose in the matcher's terms: its centre (x, y, height) on the head, the heading
// and tilt of its optical axis f (atan2(f_y, f_x), asin(-f_z)) and its roll about f
// (RobotPoseFromCamFromWorld of CamFromWorldOnHead); for a camera aligned with the tilt frame on
// a level base these are base heading + pan, the head's tilt (the paper's "tilt known but
// variable" case) and no roll.
RobotPose CameraPoseOnHead(const HeadGeometry& geometry, const Pose3Dof& base,
                           double crossing_height, double pan, double tilt);

// Head angles that put the world point `target` on the optical axis (the image centre), pan in
// (-pi, pi]: Newton's method on the target's normalised image coordinates (x/z, y/z), started from
// the closed form of a camera aligned with the tilt frame (p'_y = offset_y fixes the pan,
// p'_x sin(tilt) + p'_z cos(tilt) = offset_z the tilt) corrected by the mount's rotation. False
// when it finds no angles with the target in front (a target too close to the axes for the
// camera's offset).
bool HeadAnglesLookingAt(const HeadGeometry& geometry, const Eigen::Isometry3d& world_from_base,
                         const Eigen::Vector3d& target, double* pan, double* tilt);

}  // namespace linetrack
