// Kinematics of a camera on a pan-tilt head for visual servoing and the robot's camera pose. The
// camera's mount is a full rigid transform tilt_from_camera (models/pan_tilt.h frames), either
// the nominal geometry of a head ViSP models (vpPtu46, vpBiclops) or a calibrated one
// (calibration/mount_calibration.h); the head's base may sit tilted on the robot. Joint
// conventions: pan counter-clockwise seen from above, tilt positive down (pan_tilt_head.h).
#pragma once

#include <visp3/core/vpMatrix.h>
#include <visp3/core/vpVelocityTwistMatrix.h>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

namespace linetrack {

enum class HeadModel {
  kPtu46,    // vpPtu46: camera upright, 0.0765 m left of and 0.068 m above the axes' crossing
  kBiclops,  // vpBiclops (DH1): camera upside down, 0.048 m below the crossing
};

// "ptu46" or "biclops"; false otherwise.
bool ParseHeadModel(const std::string& name, HeadModel* model);

// How a camera sits about its optical axis when that axis is the tilt frame's x axis.
enum class CameraRoll { kUpright, kUpsideDown };

// tilt_from_camera of a camera looking along the tilt frame's x axis with its centre at `centre`
// (tilt frame, metres): upright, image x to the right (-y_tilt) and image y down (-z_tilt), or
// rolled 180 degrees about the optical axis.
Eigen::Isometry3d AlignedMount(const Eigen::Vector3d& centre, CameraRoll roll);

// Where the camera sits on the head, and the head on the robot.
struct HeadGeometry {
  // The camera's pose on the tilting part (tilt frame: x forward at zero tilt, y left, z up,
  // origin where the pan and tilt axes cross). Default: upright at the crossing.
  Eigen::Isometry3d tilt_from_camera = AlignedMount(Eigen::Vector3d::Zero(), CameraRoll::kUpright);
  // The base's tilt on the robot, level_from_base = LevelFromBaseRotation(roll, pitch)
  // (models/pan_tilt.h); identity for a level base.
  Eigen::Matrix3d level_from_base = Eigen::Matrix3d::Identity();

  // Finite, both rotations orthonormal with determinant +1, the camera within 1 m of the crossing.
  bool Check(std::string* why) const;
};

// The nominal geometry of `model` (constants of vpPtu46 / vpBiclops), base level.
HeadGeometry GeometryOf(HeadModel model);

// Camera pose in the head's base frame: base_from_camera = Rz(pan) Ry(tilt) tilt_from_camera,
// where Ry(tilt) takes the forward axis to (cos tilt, 0, -sin tilt).
Eigen::Isometry3d BaseFromCamera(const HeadGeometry& geometry, double pan, double tilt);

// ViSP's matrices for vpServo::set_cVe / set_eJe (EYEINHAND_L_cVe_eJe) with the tilt frame as
// ViSP's end effector e: eJe maps (pan_rate, tilt_rate) to the tilt frame's twist in its own axes
// (v = 0: its origin is the crossing; w = pan_rate Ry(tilt)^T z + tilt_rate y), and cVe is the
// twist transform of camera_from_tilt. Camera twist (v [m/s], w [rad/s]) = cVe eJe q_dot; neither
// depends on the pan.
struct HeadServoMatrices {
  vpVelocityTwistMatrix cVe;
  vpMatrix eJe;  // 6 x 2
};
HeadServoMatrices ServoMatricesOf(const HeadGeometry& geometry, double tilt);

// cVe * eJe of ServoMatricesOf as a 6x2 Eigen matrix (the pan does not enter it).
Eigen::Matrix<double, 6, 2> CameraJacobian(const HeadGeometry& geometry, double tilt);

}  // namespace linetrack
