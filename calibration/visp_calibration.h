// Zhang-style calibration through ViSP's vpCalibration as ViSP's calibration tutorial runs it:
// each view is first calibrated alone by virtual visual servoing (CALIB_VIRTUAL_VS, gain 0.5,
// starting from ViSP's default focal length and the image centre, each view starting from the
// previous view's result), then all views together without distortion (CALIB_VIRTUAL_VS), then
// with ViSP's one-term radial distortion (CALIB_VIRTUAL_VS_DIST; kud and kdu, models/camera.h).
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calibration/board_view.h"
#include "models/camera.h"

namespace linetrack {

struct VispCalibrationOptions {
  double gain = 0.5;           // vpCalibration::setLambda, as in ViSP's tutorial
  double aspect_ratio = -1.0;  // > 0: px / py fixed to this value (vpCalibration::setAspectRatio)

  bool Check(std::string* why) const;
};

// Both models ViSP estimates, their errors and the standard deviations of the distorted model.
struct VispCalibration {
  bool ok = false;
  std::string failure;       // why not ok
  CameraIntrinsics without;  // perspectiveProjWithoutDistortion
  CameraIntrinsics with;     // perspectiveProjWithDistortion (has_distortion, kud, kdu)
  // ViSP's global reprojection errors (pixels) as computeCalibrationMulti returns them.
  double global_error_without = 0.0, global_error_with = 0.0;
  // Per-view RMS reprojection errors (pixels), recomputed from the poses and models.
  std::vector<double> view_error_without, view_error_with;
  std::vector<Eigen::Isometry3d> cam_from_board_with;  // poses under the distorted model
  // Standard deviations of px, py, u0, v0, kud (pixels; kud unitless) of the distorted model,
  // from the Gauss-Newton covariance s^2 (J^T J)^-1 over intrinsics and all poses.
  Eigen::Matrix<double, 5, 1> std_dev_with = Eigen::Matrix<double, 5, 1>::Zero();
};

// Calibrates from at least 3 views (image size in pixels). Expected failures (ViSP diverges or
// refuses) come back with ok = false; vpException never escapes.
VispCalibration CalibrateWithVisp(const std::vector<BoardView>& views, int width, int height,
                                  const VispCalibrationOptions& options);

// Pixel of a board point seen from `cam_from_board` under `camera` (with its distortion).
Eigen::Vector2d ProjectBoardPoint(const CameraIntrinsics& camera,
                                  const Eigen::Isometry3d& cam_from_board,
                                  const Eigen::Vector3d& board_point);

// Standard deviations of (px, py, u0, v0, kud) of `camera` (with distortion) given the views
// and their poses: numerical Jacobian of all residuals over the 5 intrinsics and 6 parameters
// per pose, covariance s^2 (J^T J)^-1 with s^2 = SSE / (2N - P). Zeros when singular.
Eigen::Matrix<double, 5, 1> VispModelStdDev(const std::vector<BoardView>& views,
                                            const CameraIntrinsics& camera,
                                            const std::vector<Eigen::Isometry3d>& cam_from_board);

}  // namespace linetrack
