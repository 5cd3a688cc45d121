// The pose of a calibration board seen by a camera whose intrinsics are known: OpenCV's planar
// PnP (IPPE, Collins and Bartoli 2014) on the undistorted points, then Levenberg-Marquardt on the
// pixel reprojection error under the camera's own model (ViSP's kud distortion), with the
// pose's covariance.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

#include "calibration/board_view.h"
#include "calibration/pose_least_squares.h"
#include "models/camera.h"

namespace linetrack {

struct BoardPose {
  bool ok = false;
  std::string failure;  // why not ok
  Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
  double rms_px = 0.0;  // RMS reprojection error over the view's points
  // Covariance of MovedPose's (shift, rotation vector) of cam_from_board, in the camera frame.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

// Residuals (projected minus detected, pixels: u then v per point) of one view at
// poses = {cam_from_board}, with their analytic Jacobian (SolvePoseLeastSquares' conventions).
// It refers to `camera` and `view`, which must outlive it.
PoseResiduals BoardViewResiduals(const CameraIntrinsics& camera, const BoardView& view);

// The board's pose in the camera from at least 4 points of one view.
BoardPose EstimateBoardPose(const CameraIntrinsics& camera, const BoardView& view,
                            const PoseLeastSquaresOptions& options = {});

}  // namespace linetrack
