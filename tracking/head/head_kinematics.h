// Kinematics of pan-tilt heads for visual servoing. ViSP ships the models of the Directed
// Perception PTU-46 (vpPtu46) and of the Biclops (vpBiclops) but no drivers; these helpers give
// their matrices in the project's joint conventions (pan counter-clockwise from above, tilt
// positive down; pan_tilt_head.h), plus an independent forward model to check them against.
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

// Where the camera sits on the tilting part. Tilt frame: x forward (the optical axis at zero
// tilt), y left, z up, origin where the pan and tilt axes cross.
struct HeadGeometry {
  Eigen::Vector3d camera_offset = Eigen::Vector3d::Zero();  // camera centre, tilt frame (m)
  bool camera_upside_down = false;  // camera rolled 180 degrees about its optical axis
};

// The geometry of ViSP's model of `model` (constants of vpPtu46 / vpBiclops).
HeadGeometry GeometryOf(HeadModel model);

// Camera pose in the head's base frame (x forward at pan 0, y left, z up; origin at the axes'
// crossing): base_from_camera = Rz(pan) Ry(tilt) [R_tilt_cam | offset], where Ry(tilt) takes
// the forward axis to (cos tilt, 0, -sin tilt) and the camera axes follow ViSP's (x right,
// y down, z forward) unless upside down. Built from first principles, not from ViSP.
Eigen::Isometry3d BaseFromCamera(const HeadGeometry& geometry, double pan, double tilt);

// ViSP's matrices for vpServo::set_cVe / set_eJe (EYEINHAND_L_cVe_eJe), with eJe expressed for
// the project's joint rates: camera twist (v [m/s], w [rad/s], camera frame) = cVe eJe
// (pan_rate, tilt_rate)^T.
struct HeadServoMatrices {
  vpVelocityTwistMatrix cVe;
  vpMatrix eJe;  // 6 x 2
};
HeadServoMatrices ServoMatricesOf(HeadModel model, double pan, double tilt);

// cVe * eJe of ServoMatricesOf as a 6x2 Eigen matrix.
Eigen::Matrix<double, 6, 2> CameraJacobian(HeadModel model, double pan, double tilt);

}  // namespace linetrack
