// The head's height above the floor and its base's tilt, from one view of the calibration board
// lying flat on the floor (`linetrack calibrate-mount --floor-board`, docs/calibration.md). With
// the calibrated mount the board's pose in the head's base frame is
//   base_from_board = Rz(pan) Ry(tilt) tilt_from_camera cam_from_board;
// the board's plane is the floor raised by the board's thickness. Its upward unit normal n in the
// base frame gives the crossing's height h = n . (0 - t_board) + thickness and the base's tilt on
// the floor, level_from_base = Ry(pitch) Rx(roll) with n = (-sin pitch, sin roll cos pitch,
// cos roll cos pitch) (models/pan_tilt.h). The base's yaw on the robot is not observed: the
// robot's forward is the base's x axis (pan zero) on the floor.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

#include "calibration/board_view.h"
#include "calibration/mount_calibration.h"
#include "models/camera.h"

namespace linetrack {

// The floor seen from the head's base.
struct FloorGeometry {
  double crossing_height = 0.0;  // the axes' crossing above the floor (metres)
  double base_roll = 0.0;        // radians, LevelFromBaseRotation's
  double base_pitch = 0.0;
};

// The floor from the board's pose in the base frame (board on the floor, printed face up, its
// surface `board_thickness` metres above the floor). The normal's sign is the one that puts the
// crossing above the board.
FloorGeometry FloorFromBoardPose(const Eigen::Isometry3d& base_from_board, double board_thickness);

struct FloorCalibration {
  bool ok = false;
  std::string failure;  // why not ok
  FloorGeometry floor;
  // Covariance of (crossing height m, roll rad, pitch rad), from the board pose's covariance and
  // the mount's (first order, numerical derivatives).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double rms_px = 0.0;  // the board pose's RMS reprojection error
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
  double camera_height = 0.0;  // the camera centre above the floor with the head level
};

// The floor from one view of the board on the floor at `angles`, seen by `camera`, with the mount
// and its covariance (MountCalibration's parameterisation).
FloorCalibration CalibrateFloor(const CameraIntrinsics& camera, const BoardView& view,
                                const HeadAngles& angles, const Eigen::Isometry3d& tilt_from_camera,
                                const Eigen::Matrix<double, 6, 6>& mount_covariance,
                                double board_thickness);

}  // namespace linetrack
