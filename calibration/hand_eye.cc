#include "calibration/hand_eye.h"

#include <fcntl.h>
#include <unistd.h>
#include <visp3/core/vpException.h>
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/vision/vpHandEyeCalibration.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "models/pan_tilt.h"

namespace linetrack {
namespace {

constexpr double kRotationTolerance = 1e-6;

// Sends the process's stdout (file descriptor 1, so printf and std::cout alike) to /dev/null
// while it lives; restores it after.
class ScopedStdoutToNull {
 public:
  ScopedStdoutToNull() {
    std::cout.flush();
    std::fflush(stdout);
    saved_ = dup(STDOUT_FILENO);
    const int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) dup2(null, STDOUT_FILENO);
    if (null >= 0) close(null);
  }
  ~ScopedStdoutToNull() {
    std::cout.flush();
    std::fflush(stdout);
    if (saved_ >= 0) {
      dup2(saved_, STDOUT_FILENO);
      close(saved_);
    }
  }
  ScopedStdoutToNull(const ScopedStdoutToNull&) = delete;
  ScopedStdoutToNull& operator=(const ScopedStdoutToNull&) = delete;

 private:
  int saved_ = -1;
};

}  // namespace

vpHomogeneousMatrix VispHomogeneous(const Eigen::Isometry3d& t) {
  vpHomogeneousMatrix m;
  for (unsigned r = 0; r < 3; ++r) {
    for (unsigned c = 0; c < 3; ++c)
      m[r][c] = t.linear()(r, c);
    m[r][3] = t.translation()(r);
  }
  return m;
}

Eigen::Isometry3d FromVispHomogeneous(const vpHomogeneousMatrix& m) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (unsigned r = 0; r < 3; ++r) {
    for (unsigned c = 0; c < 3; ++c)
      t.linear()(r, c) = m[r][c];
    t.translation()(r) = m[r][3];
  }
  return t;
}

HandEyeStart HandEyeMount(const std::vector<Eigen::Matrix3d>& base_from_tilt,
                          const std::vector<Eigen::Isometry3d>& cam_from_board) {
  HandEyeStart out;
  if (base_from_tilt.size() != cam_from_board.size() || base_from_tilt.size() < 3) {
    out.failure = "hand-eye: at least 3 views with both the head's angles and the board's pose";
    return out;
  }
  std::vector<vpHomogeneousMatrix> rMe, cMo;
  for (size_t i = 0; i < base_from_tilt.size(); ++i) {
    Eigen::Isometry3d rotation = Eigen::Isometry3d::Identity();
    rotation.linear() = base_from_tilt[i];
    rMe.push_back(VispHomogeneous(rotation));
    cMo.push_back(VispHomogeneous(cam_from_board[i]));
  }
  vpHomogeneousMatrix eMc;
  try {
    const ScopedStdoutToNull quiet;
    out.visp_status = vpHandEyeCalibration::calibrate(cMo, rMe, eMc);
  } catch (const vpException& e) {
    out.failure = std::string("ViSP's hand-eye calibration: ") + e.getMessage();
    return out;
  }
  out.tilt_from_camera = FromVispHomogeneous(eMc);
  const Eigen::Matrix3d r = out.tilt_from_camera.linear();
  if (!out.tilt_from_camera.matrix().allFinite() ||
      (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > kRotationTolerance) {
    out.failure = "ViSP's hand-eye calibration gave no rigid transform (status " +
                  std::to_string(out.visp_status) + ")";
    return out;
  }
  out.ok = true;
  return out;
}

double RotationAxisSpread(const std::vector<Eigen::Matrix3d>& base_from_tilt) {
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < base_from_tilt.size(); ++i) {
    for (size_t j = i + 1; j < base_from_tilt.size(); ++j) {
      const Eigen::Vector3d w =
          VectorFromRotation(base_from_tilt[j].transpose() * base_from_tilt[i]);
      scatter += w * w.transpose();
    }
  }
  const Eigen::Vector3d l =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter, Eigen::EigenvaluesOnly)
          .eigenvalues();  // ascending
  if (!(l[2] > 0.0)) return 0.0;
  return std::sqrt(std::max(0.0, l[1]) / l[2]);
}

}  // namespace linetrack
