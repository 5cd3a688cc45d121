#include "calibration/floor_calibration.h"

#include <algorithm>
#include <cmath>

#include "calibration/board_pose.h"
#include "models/pan_tilt.h"

namespace linetrack {
namespace {

constexpr double kDerivativeStep = 1e-7;  // metres or radians, central differences

Eigen::Vector3d FloorVector(const HeadAngles& angles, const Eigen::Isometry3d& mount,
                            const Eigen::Isometry3d& cam_from_board, double thickness) {
  Eigen::Isometry3d base_from_tilt = Eigen::Isometry3d::Identity();
  base_from_tilt.linear() = BaseFromTiltRotation(angles.pan, angles.tilt);
  const FloorGeometry f = FloorFromBoardPose(base_from_tilt * mount * cam_from_board, thickness);
  return {f.crossing_height, f.base_roll, f.base_pitch};
}

}  // namespace

FloorGeometry FloorFromBoardPose(const Eigen::Isometry3d& base_from_board, double board_thickness) {
  Eigen::Vector3d up = base_from_board.linear().col(2);
  const Eigen::Vector3d& origin = base_from_board.translation();
  if (up.dot(-origin) < 0.0) up = -up;  // the crossing lies above the board
  FloorGeometry floor;
  floor.crossing_height = up.dot(-origin) + board_thickness;
  floor.base_pitch = std::asin(std::clamp(-up.x(), -1.0, 1.0));
  floor.base_roll = std::atan2(up.y(), up.z());
  return floor;
}

FloorCalibration CalibrateFloor(const CameraIntrinsics& camera, const BoardView& view,
                                const HeadAngles& angles, const Eigen::Isometry3d& tilt_from_camera,
                                const Eigen::Matrix<double, 6, 6>& mount_covariance,
                                double board_thickness) {
  FloorCalibration out;
  const BoardPose pose = EstimateBoardPose(camera, view);
  if (!pose.ok) {
    out.failure = "the floor board: " + pose.failure;
    return out;
  }
  out.cam_from_board = pose.cam_from_board;
  out.rms_px = pose.rms_px;
  const Eigen::Vector3d value =
      FloorVector(angles, tilt_from_camera, pose.cam_from_board, board_thickness);
  out.floor = {value[0], value[1], value[2]};
  // First-order propagation over the mount's delta (6) and the board pose's delta (6).
  Eigen::Matrix<double, 3, 12> jacobian;
  for (int j = 0; j < 12; ++j) {
    Eigen::Matrix<double, 6, 1> step = Eigen::Matrix<double, 6, 1>::Zero();
    step[j % 6] = kDerivativeStep;
    const bool mount = j < 6;
    auto at = [&](double sign) {
      return FloorVector(angles,
                         mount ? MovedPose(tilt_from_camera, sign * step) : tilt_from_camera,
                         mount ? pose.cam_from_board : MovedPose(pose.cam_from_board, sign * step),
                         board_thickness);
    };
    jacobian.col(j) = (at(1.0) - at(-1.0)) / (2.0 * kDerivativeStep);
  }
  Eigen::Matrix<double, 12, 12> covariance = Eigen::Matrix<double, 12, 12>::Zero();
  covariance.topLeftCorner<6, 6>() = mount_covariance;
  covariance.bottomRightCorner<6, 6>() = pose.covariance;
  out.covariance = jacobian * covariance * jacobian.transpose();
  const Eigen::Matrix3d level = LevelFromBaseRotation(out.floor.base_roll, out.floor.base_pitch);
  out.camera_height = out.floor.crossing_height + (level * tilt_from_camera.translation()).z();
  out.ok = true;
  return out;
}

}  // namespace linetrack
