// The pose covariance as ROS wants it (geometry_msgs/PoseWithCovariance): the pose of the robot's
// base, 6 x 6 over (x, y, z, roll, pitch, yaw), the angles those of R = Rz(yaw) Ry(pitch)
// Rx(roll) (rotations about the fixed X, Y, Z axes of the world). docs/integrity.md, section 1.
#pragma once

#include <Eigen/Geometry>

namespace linetrack {

// (roll, pitch, yaw) of a rotation R = Rz(yaw) Ry(pitch) Rx(roll), pitch in [-pi/2, pi/2].
Eigen::Vector3d RollPitchYaw(const Eigen::Matrix3d& rotation);

// The base's covariance over (x, y, z, roll, pitch, yaw) from the camera's world-twist covariance
// (dC, omega; WorldTwistCovariance) at cam_from_world, `base_from_cam` the camera's pose on the
// base. To first order the base's origin moves by dC - [R_wc t]x omega (t the base's origin in the
// camera frame) and turns by omega = E d(roll, pitch, yaw), E = [Rz Ry e_x, Rz e_y, e_z].
Eigen::Matrix<double, 6, 6> RosBaseCovariance(const Eigen::Matrix<double, 6, 6>& twist_covariance,
                                              const Eigen::Isometry3d& cam_from_world,
                                              const Eigen::Isometry3d& base_from_cam);

}  // namespace linetrack
