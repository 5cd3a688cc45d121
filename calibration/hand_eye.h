// The closed-form start of a camera's mount on a pan-tilt head, from ViSP's hand-eye calibration
// (vpHandEyeCalibration::calibrate, ViSP 3.5: Tsai-Lenz and Procrustes rotations, two linear
// translation solutions, the best of the six refined by ViSP's virtual visual servoing on the
// pairs of views), with the tilt frame as ViSP's end effector e and the head's base as its
// reference r: rMe = base_from_tilt, cMo = cam_from_board, eMc = tilt_from_camera. And the test
// that the head turned about more than one axis, without which the mount is not observable.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace linetrack {

// ViSP's homogeneous matrix of a rigid transform, and back (same frames, same units).
vpHomogeneousMatrix VispHomogeneous(const Eigen::Isometry3d& t);
Eigen::Isometry3d FromVispHomogeneous(const vpHomogeneousMatrix& m);

struct HandEyeStart {
  bool ok = false;
  std::string failure;  // why not ok
  // ViSP's status: 0 converged, 1 its refinement did not converge (eMc is then its last
  // iterate), -1 a rank deficiency.
  int visp_status = 0;
  Eigen::Isometry3d tilt_from_camera = Eigen::Isometry3d::Identity();
};

// ViSP's hand-eye estimate of tilt_from_camera from at least 3 views: the head's rotation
// base_from_tilt and the board's pose cam_from_board in each. ViSP 3.5 prints its progress on
// stdout (printf and std::cout); the process's stdout is silenced during the call (not
// thread-safe). vpException is caught; ok = false when ViSP's answer is not a rigid transform.
HandEyeStart HandEyeMount(const std::vector<Eigen::Matrix3d>& base_from_tilt,
                          const std::vector<Eigen::Isometry3d>& cam_from_board);

// How much the head's rotation axes spread across the views: with w the rotation vector of
// R_j^T R_i (view i seen from view j's tilt frame) for every pair i < j and l1 >= l2 >= l3 the
// eigenvalues of sum w w^T, sqrt(l2 / l1); 0 when every turn is about one axis (the mount's
// position along that axis is then unobservable), up to 1. 0 for fewer than two views.
double RotationAxisSpread(const std::vector<Eigen::Matrix3d>& base_from_tilt);

}  // namespace linetrack
