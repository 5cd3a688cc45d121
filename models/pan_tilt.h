// Pan-tilt head kinematics shared by the mount calibration (calibration/) and the head's use
// (tracking/head/). Frames: the head's base (x forward at pan 0, y left, z up, origin where the
// pan and tilt axes cross) and the tilt frame (the same axes carried by pan, then by tilt). Pan is
// counter-clockwise seen from above, tilt positive looking down. A camera's mount on the head is
// tilt_from_camera (ViSP camera axes: x right, y down, z forward; metres).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace linetrack {

// base_from_tilt = Rz(pan) Ry(tilt): Ry(tilt) takes the forward axis x to (cos t, 0, -sin t).
inline Eigen::Matrix3d BaseFromTiltRotation(double pan, double tilt) {
  return (Eigen::AngleAxisd(pan, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()))
      .toRotationMatrix();
}

// Rotation of the rotation vector w (axis w / |w|, angle |w| radians): the exponential map.
inline Eigen::Matrix3d RotationFromVector(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (!(angle > 0.0)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

// Rotation vector of a rotation (inverse of RotationFromVector, angle in [0, pi]).
inline Eigen::Vector3d VectorFromRotation(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

// A pose moved by delta = (shift, rotation vector), both in the pose's parent frame (metres,
// radians): translation t + shift, rotation Exp(rotation) R. The parameterisation of the mount's
// covariance (the tilt frame is the mount's parent).
inline Eigen::Isometry3d MovedPose(const Eigen::Isometry3d& pose,
                                   const Eigen::Matrix<double, 6, 1>& delta) {
  Eigen::Isometry3d moved = Eigen::Isometry3d::Identity();
  moved.linear() = RotationFromVector(delta.tail<3>()) * pose.linear();
  moved.translation() = pose.translation() + delta.head<3>();
  return moved;
}

// The delta that MovedPose applies to `from` to give `to`: (t_to - t_from, Log(R_to R_from^T)).
inline Eigen::Matrix<double, 6, 1> PoseDelta(const Eigen::Isometry3d& to,
                                             const Eigen::Isometry3d& from) {
  Eigen::Matrix<double, 6, 1> delta;
  delta.head<3>() = to.translation() - from.translation();
  delta.tail<3>() = VectorFromRotation(to.linear() * from.linear().transpose());
  return delta;
}

// level_from_base of a head base tilted on the robot: Ry(pitch) Rx(roll). Pitch positive tips
// the base's forward axis down (like the head's tilt), roll positive lifts its left side; the
// base's forward axis keeps the robot's heading (no yaw).
inline Eigen::Matrix3d LevelFromBaseRotation(double roll, double pitch) {
  return (Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace linetrack
