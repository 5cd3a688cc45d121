// Zhang-style calibration through ViSP's vpCalibration as ViSP's calibration tutorial runs it:
// each view is first calibrated alone by virtual visual servoing (CALIB_VIRTUAL_VS, gain 0.5,
// starting from ViSP's default focal length and the image centre, each view starting from the
// previous view's result), then all views together without distortion (CALIB_VIRTUAL_VS), then
// with ViSP's one-term radial distortion (CALIB_VIRTUAL_VS_DIST; kud and kdu, models/camera.h).
// ViSP's distorted estimate balances kud against kdu (which is not kud's exact inverse), which
// biases it even on exact data (docs/calibration.md); a final Levenberg-Marquardt refinement
// minimises the pixel reprojection error of the kud model alone and refits kdu as its inverse.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calibration/board_view.h"
#include "models/camera.h"

namespace linetrack {

struct VispCalibrationOptions {
  double gain = 0.5;   // vpCalibration::setLambda, as in ViSP's tutorial
  bool refine = true;  // refine ViSP's distorted model on the pixel reprojection error
  int refine_iterations = 50;

  bool Check(std::string* why) const;
};

// Both models ViSP estimates, their errors and the standard deviations of the distorted model.
struct VispCalibration {
  bool ok = false;
  std::string failure;       // why not ok
  CameraIntrinsics without;  // perspectiveProjWithoutDistortion
  CameraIntrinsics with;     // perspectiveProjWithDistortion as ViSP estimates it
  // The distorted model written out: `with` refined (options.refine), else `with` itself.
  CameraIntrinsics final_model;
  bool refined =
      false;  // ViSP's global reprojection errors (pixels) as computeCalibrationMulti returns them.
  double global_error_without = 0.0, global_error_with = 0.0;
  // Per-view RMS reprojection errors (pixels) under each model, and the final model's RMS over
  // all points.
  std::vector<double> view_error_without, view_error_with, view_error_final;
  double rms_final = 0.0;
  std::vector<Eigen::Isometry3d> cam_from_board_final;  // poses under the final model
  // Standard deviations of px, py, u0, v0, kud (pixels; kud unitless) of the final model, from
  // the Gauss-Newton covariance s^2 (J^T J)^-1 over intrinsics and all poses.
  Eigen::Matrix<double, 5, 1> std_dev = Eigen::Matrix<double, 5, 1>::Zero();
};

// Calibrates from at least 3 views (image size in pixels). Expected failures (ViSP diverges or
// refuses) come back with ok = false; vpException never escapes.
VispCalibration CalibrateWithVisp(const std::vector<BoardView>& views, int width, int height,
                                  const VispCalibrationOptions& options);

// Pixel of a board point seen from `cam_from_board` under `camera` (with its distortion).
Eigen::Vector2d ProjectBoardPoint(const CameraIntrinsics& camera,
                                  const Eigen::Isometry3d& cam_from_board,
                                  const Eigen::Vector3d& board_point);

// Levenberg-Marquardt on the pixel reprojection error of ViSP's kud model over (px, py, u0, v0,
// kud) and every pose (numerical Jacobian), from `camera` and `cam_from_board`, updated in place.
// Returns false (and leaves both unchanged) when no step lowered the error.
bool RefineVispModel(const std::vector<BoardView>& views, int iterations, CameraIntrinsics* camera,
                     std::vector<Eigen::Isometry3d>* cam_from_board);

// kdu that best inverts `camera`'s kud over its image: least squares of
// x_d (1 + kdu |x_d|^2) = x on a grid of distorted pixels, x the exact undistorted point.
double FitKdu(const CameraIntrinsics& camera);

// Standard deviations of (px, py, u0, v0, kud) of `camera` (with distortion) given the views
// and their poses: numerical Jacobian of all residuals over the 5 intrinsics and 6 parameters
// per pose, covariance s^2 (J^T J)^-1 with s^2 = SSE / (2N - P). Zeros when singular.
Eigen::Matrix<double, 5, 1> VispModelStdDev(const std::vector<BoardView>& views,
                                            const CameraIntrinsics& camera,
                                            const std::vector<Eigen::Isometry3d>& cam_from_board);

}  // namespace linetrack
