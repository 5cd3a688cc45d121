// Nonlinear least squares over rigid poses, for the calibrations that know the intrinsics (a
// board's pose, the camera's mount on a pan-tilt head): the pixel projection of ViSP's kud model
// with its derivative, and Levenberg-Marquardt over several poses, each updated by MovedPose
// (translation + shift, rotation Exp(w) R; models/pan_tilt.h) so that the covariance it returns
// is that of the (shift, w) 6-vectors.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <string>
#include <vector>

#include "models/camera.h"

namespace linetrack {

// Which one-term radial model maps undistorted to distorted pixels (docs/conventions.md).
enum class DistortionModel {
  kKud,          // ViSP's projection: x_d = x (1 + kud |x|^2), what `calibrate` fits
  kInverseOfKdu  // x_d solving x_d (1 + kdu |x_d|^2) = x: what the scene renderer draws
};

// Pixel of the camera-frame point p (z > 0) under `camera`: u0 + px x_d, v0 + py y_d with x_d
// the distorted image of (x, y) = (X / Z, Y / Z) under `model` (x_d = x without distortion),
// and the derivative d(u, v) / dp when `d_pixel_d_point` is not null.
Eigen::Vector2d ProjectPoint(const CameraIntrinsics& camera, const Eigen::Vector3d& p,
                             Eigen::Matrix<double, 2, 3>* d_pixel_d_point,
                             DistortionModel model = DistortionModel::kKud);

// The cross-product matrix [v]x: [v]x a = v x a.
Eigen::Matrix3d SkewMatrix(const Eigen::Vector3d& v);

// Residuals r of the poses and, when `jacobian` is not null, dr / d(delta) where delta stacks
// one (shift, rotation vector) 6-vector per pose (columns 6k .. 6k + 5 for pose k). Returns false
// when the residuals cannot be evaluated (a point behind the camera).
using PoseResiduals = std::function<bool(const std::vector<Eigen::Isometry3d>& poses,
                                         Eigen::VectorXd* r, Eigen::MatrixXd* jacobian)>;

struct PoseLeastSquaresOptions {
  int max_iterations = 100;
  double initial_damping = 1e-4;  // lambda, relative to the diagonal of J^T J
  // Converged when a step lowers the cost by less than this fraction of it.
  double relative_tolerance = 1e-12;

  bool Check(std::string* why) const;
};

struct PoseLeastSquaresResult {
  bool ok = false;
  std::string failure;  // why not ok
  int iterations = 0;
  double cost = 0.0;  // sum of squared residuals at the result
  int residuals = 0;
  // s^2 (J^T J)^-1 with s^2 = cost / (residuals - parameters): the covariance of delta at the
  // result (empty when not ok).
  Eigen::MatrixXd covariance;
};

// Levenberg-Marquardt with Marquardt's diagonal scaling on |r|^2 from `poses`, updated in place.
// Fails (poses unchanged) when the residuals cannot be evaluated at the start, there are no more
// residuals than parameters, or J^T J is singular at the result (a direction not observed).
PoseLeastSquaresResult SolvePoseLeastSquares(const PoseResiduals& residuals,
                                             const PoseLeastSquaresOptions& options,
                                             std::vector<Eigen::Isometry3d>* poses);

// Central-difference Jacobian of `residuals` at `poses` (step h on each delta component): for
// checking analytic Jacobians. Empty when the residuals cannot be evaluated.
Eigen::MatrixXd NumericPoseJacobian(const PoseResiduals& residuals,
                                    const std::vector<Eigen::Isometry3d>& poses, double h);

}  // namespace linetrack
