// The camera's mount on a pan-tilt head (`linetrack calibrate-mount`, docs/calibration.md): a
// board stands still while the head turns; each view gives the board's pose in the camera
// (known intrinsics) and the head's angles give base_from_tilt = Rz(pan) Ry(tilt)
// (models/pan_tilt.h). ViSP's hand-eye calibration starts the mount tilt_from_camera
// (hand_eye.h); one joint Levenberg-Marquardt then refines the mount and the board's pose in the
// base frame over every corner's reprojection:
//   pixel_ik = project(tilt_from_camera^-1 Rz(pan_i) Ry(tilt_i))^T base_from_board X_k),
// with the mount's 6x6 covariance. Views where the board is not found, blurred, or whose error
// is an outlier are named and left out, as `linetrack calibrate` does (calibrate.h).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calibration/calibrate.h"
#include "calibration/detection.h"
#include "calibration/pattern.h"
#include "calibration/pose_least_squares.h"
#include "models/camera.h"

namespace linetrack {

// The head's joint angles of one view (radians; pan counter-clockwise from above, tilt positive
// down).
struct HeadAngles {
  double pan = 0.0;
  double tilt = 0.0;
};

struct MountCalibrationOptions {
  PatternSpec pattern;
  DetectionOptions detection;
  PoseLeastSquaresOptions solver;
  // Outlier views, as CalibrationOptions: the worst view (RMS error under the joint estimate) is
  // dropped while it exceeds both outlier_factor times the median and outlier_min_error_px.
  bool reject_outliers = true;
  double outlier_factor = 3.0;
  double outlier_min_error_px = 0.5;
  int min_views = 4;  // fewer usable views: refused
  // RotationAxisSpread of the views below this: the head turned about one axis only.
  double min_axis_spread = 0.05;
  // The camera's distortion in the joint refinement: kud (a camera from `calibrate`), or the
  // inverse of kdu for images the scene renderer drew (the simulated camera).
  DistortionModel distortion = DistortionModel::kKud;
  // The displacement shared by all points of a view (pixels per image axis, view_shift.h): < 0
  // estimated from the residuals; >= 0 known, e.g. f q / sqrt(12) for logged head angles rounded
  // to steps of q radians.
  double view_shift_px = -1.0;

  bool Check(std::string* why) const;
};

enum class MountStatus {
  kOk,
  kPatternNeverFound,  // bad input: no image shows the board
  kTooFewViews,        // fewer than min_views usable views
  kUnobservable,       // the usable views turn about one axis only
  kEstimationFailed,   // the hand-eye start or the refinement failed
};

struct MountViewReport {
  std::string name;
  HeadAngles angles;
  ViewStatus status = ViewStatus::kPatternNotFound;
  std::string reason;  // why rejected, with the figures (empty when used)
  PatternDetection detection;
  double pose_error_px = -1.0;  // RMS error of the view's own board pose (-1: none)
  // RMS error under the last joint estimate that used the view (-1: never used), and its points'
  // residuals there (detected minus predicted, pixels, in detection order).
  double error_px = -1.0;
  std::vector<Eigen::Vector2d> residuals;
};

struct MountCalibration {
  MountStatus status = MountStatus::kEstimationFailed;
  std::string message;                 // one line explaining a failure
  std::vector<MountViewReport> views;  // one per image, in input order
  Eigen::Isometry3d tilt_from_camera = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d base_from_board = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d hand_eye_start = Eigen::Isometry3d::Identity();  // ViSP's
  int hand_eye_status = 0;                                           // HandEyeStart::visp_status
  // Covariance of the mount's MovedPose delta (shift in metres, rotation vector in radians, both
  // in the tilt frame: tilt_from_camera = (t + shift, Exp(w) R)): the joint refinement's under
  // independent pixel noise plus a displacement shared by each view's points (view_shift.h; the
  // intrinsics taken as exact).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  double noise_sigma_px = 0.0;      // the independent noise per coordinate (pixels)
  double view_shift_px = 0.0;       // the shared displacement per axis in `covariance` (pixels)
  double view_shift_data_px = 0.0;  // its estimate from the residuals alone (pixels)
  double rms_px = 0.0;              // over every point of the used views
  double axis_spread = 0.0;         // RotationAxisSpread of the used views
  int rejection_rounds = 0;

  bool ok() const { return status == MountStatus::kOk; }
  int UsedViews() const;
};

// Residuals of views (board points and detections) taken at `angles`, at poses =
// {tilt_from_camera, base_from_board}, with their analytic Jacobian (SolvePoseLeastSquares'
// conventions). It refers to its arguments, which must outlive it.
PoseResiduals MountResiduals(const CameraIntrinsics& camera, const std::vector<BoardView>& views,
                             const std::vector<HeadAngles>& angles,
                             DistortionModel model = DistortionModel::kKud);

// The calibration from detections (names, angles and detections in the same order). `camera` is
// the camera's calibrated model (with its distortion).
MountCalibration CalibrateMountFromDetections(const std::vector<std::string>& names,
                                              const std::vector<HeadAngles>& angles,
                                              const std::vector<PatternDetection>& detections,
                                              const CameraIntrinsics& camera,
                                              const MountCalibrationOptions& options);

}  // namespace linetrack
