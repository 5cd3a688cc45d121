#include "calibration/visp_calibration.h"

#include <visp3/core/vpException.h>
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/vision/vpCalibration.h>

#include <Eigen/Dense>
#include <cmath>

namespace linetrack {
namespace {

Eigen::Isometry3d ToIsometry(const vpHomogeneousMatrix& m) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      t.linear()(r, c) = m[static_cast<unsigned>(r)][static_cast<unsigned>(c)];
    t.translation()(r) = m[static_cast<unsigned>(r)][3];
  }
  return t;
}

CameraIntrinsics FromVisp(const vpCameraParameters& p, int width, int height, bool distorted) {
  CameraIntrinsics cam;
  cam.width = width;
  cam.height = height;
  cam.px = p.get_px();
  cam.py = p.get_py();
  cam.u0 = p.get_u0();
  cam.v0 = p.get_v0();
  cam.has_distortion = distorted;
  cam.kud = distorted ? p.get_kud() : 0.0;
  cam.kdu = distorted ? p.get_kdu() : 0.0;
  return cam;
}

std::vector<double> ViewErrors(const std::vector<BoardView>& views, const CameraIntrinsics& camera,
                               const std::vector<Eigen::Isometry3d>& poses) {
  std::vector<double> errors;
  for (size_t v = 0; v < views.size(); ++v) {
    std::vector<Eigen::Vector2d> projected;
    for (const Eigen::Vector3d& p : views[v].board_points)
      projected.push_back(ProjectBoardPoint(camera, poses[v], p));
    errors.push_back(RmsDistance(projected, views[v].image_points));
  }
  return errors;
}

bool AllFinite(const CameraIntrinsics& c) {
  std::string why;
  return c.Check(&why);
}

// Intrinsics vector (px, py, u0, v0, kud) <-> camera.
Eigen::Matrix<double, 5, 1> IntrinsicVector(const CameraIntrinsics& c) {
  Eigen::Matrix<double, 5, 1> x;
  x << c.px, c.py, c.u0, c.v0, c.kud;
  return x;
}

CameraIntrinsics WithIntrinsics(CameraIntrinsics c, const Eigen::Matrix<double, 5, 1>& x) {
  c.px = x(0);
  c.py = x(1);
  c.u0 = x(2);
  c.v0 = x(3);
  c.kud = x(4);
  return c;
}

// Pose moved by a rotation vector (applied on the left) and a translation step.
Eigen::Isometry3d Perturbed(const Eigen::Isometry3d& pose, int k, double step) {
  Eigen::Isometry3d out = pose;
  if (k < 3) {
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    w(k) = step;
    out.linear() = Eigen::AngleAxisd(step, w.normalized()).toRotationMatrix() * pose.linear();
  } else {
    out.translation()(k - 3) += step;
  }
  return out;
}

}  // namespace

double RmsDistance(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b) {
  if (a.empty() || a.size() != b.size()) return 0.0;
  double sum = 0.0;
  for (size_t i = 0; i < a.size(); ++i)
    sum += (a[i] - b[i]).squaredNorm();
  return std::sqrt(sum / static_cast<double>(a.size()));
}

double PooledRms(const std::vector<double>& view_rms, const std::vector<int>& counts) {
  double sum = 0.0, n = 0.0;
  for (size_t i = 0; i < view_rms.size() && i < counts.size(); ++i) {
    sum += counts[i] * view_rms[i] * view_rms[i];
    n += counts[i];
  }
  return n > 0.0 ? std::sqrt(sum / n) : 0.0;
}

bool VispCalibrationOptions::Check(std::string* why) const {
  if (!(gain > 0.0 && gain <= 1.0)) {
    *why = "ViSP calibration gain must be within (0, 1]";
    return false;
  }
  if (!std::isfinite(aspect_ratio)) {
    *why = "aspect ratio must be finite";
    return false;
  }
  return true;
}

Eigen::Vector2d ProjectBoardPoint(const CameraIntrinsics& camera,
                                  const Eigen::Isometry3d& cam_from_board,
                                  const Eigen::Vector3d& board_point) {
  return camera.Distort(camera.Project(cam_from_board * board_point));
}

VispCalibration CalibrateWithVisp(const std::vector<BoardView>& views, int width, int height,
                                  const VispCalibrationOptions& options) {
  VispCalibration result;
  if (views.size() < 3) {
    result.failure = "ViSP calibration needs at least 3 views";
    return result;
  }
  try {
    vpCalibration::setLambda(options.gain);
    // Start as ViSP's tutorial does: default focal length, principal point at the centre.
    vpCameraParameters cam;
    cam.initPersProjWithoutDistortion(cam.get_px(), cam.get_px(), width / 2, height / 2);
    std::vector<vpCalibration> calibrators;
    for (const BoardView& view : views) {
      vpCalibration calib;
      if (options.aspect_ratio > 0.0) calib.setAspectRatio(options.aspect_ratio);
      calib.clearPoint();
      for (size_t i = 0; i < view.board_points.size(); ++i) {
        const Eigen::Vector3d& p = view.board_points[i];
        vpImagePoint ip(view.image_points[i].y(), view.image_points[i].x());
        calib.addPoint(p.x(), p.y(), p.z(), ip);
      }
      vpHomogeneousMatrix cMo;
      if (calib.computeCalibration(vpCalibration::CALIB_VIRTUAL_VS, cMo, cam, false) != 0) {
        result.failure = "ViSP could not calibrate view " + view.name + " alone";
        return result;
      }
      calibrators.push_back(calib);
    }
    double error = 0.0;
    if (vpCalibration::computeCalibrationMulti(vpCalibration::CALIB_VIRTUAL_VS, calibrators, cam,
                                               error, false) != 0) {
      result.failure = "ViSP calibration without distortion failed";
      return result;
    }
    result.without = FromVisp(cam, width, height, false);
    result.global_error_without = error;
    if (vpCalibration::computeCalibrationMulti(vpCalibration::CALIB_VIRTUAL_VS_DIST, calibrators,
                                               cam, error, false) != 0) {
      result.failure = "ViSP calibration with distortion failed";
      return result;
    }
    result.with = FromVisp(cam, width, height, true);
    result.global_error_with = error;
    std::vector<Eigen::Isometry3d> poses_without;
    for (const vpCalibration& c : calibrators) {
      poses_without.push_back(ToIsometry(c.cMo));
      result.cam_from_board_with.push_back(ToIsometry(c.cMo_dist));
    }
    result.view_error_without = ViewErrors(views, result.without, poses_without);
    result.view_error_with = ViewErrors(views, result.with, result.cam_from_board_with);
  } catch (const vpException& e) {
    result.failure = std::string("ViSP calibration failed: ") + e.getMessage();
    return result;
  }
  if (!AllFinite(result.without) || !AllFinite(result.with) ||
      !std::isfinite(result.global_error_with)) {
    result.failure = "ViSP calibration diverged (non-finite or non-positive focal length)";
    return result;
  }
  result.std_dev_with = VispModelStdDev(views, result.with, result.cam_from_board_with);
  result.ok = true;
  return result;
}

Eigen::Matrix<double, 5, 1> VispModelStdDev(const std::vector<BoardView>& views,
                                            const CameraIntrinsics& camera,
                                            const std::vector<Eigen::Isometry3d>& cam_from_board) {
  const int intrinsics = 5;
  const int params = intrinsics + 6 * static_cast<int>(views.size());
  int residuals = 0;
  for (const BoardView& v : views)
    residuals += 2 * static_cast<int>(v.board_points.size());
  Eigen::Matrix<double, 5, 1> std_dev = Eigen::Matrix<double, 5, 1>::Zero();
  if (residuals <= params) return std_dev;

  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(residuals, params);
  double sse = 0.0;
  const Eigen::Matrix<double, 5, 1> x0 = IntrinsicVector(camera);
  const Eigen::Matrix<double, 5, 1> steps(1e-4 * camera.px, 1e-4 * camera.py, 1e-3, 1e-3, 1e-6);
  constexpr double kPoseStep = 1e-6;  // radians and metres
  int row = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    const BoardView& view = views[v];
    for (size_t i = 0; i < view.board_points.size(); ++i, row += 2) {
      const Eigen::Vector3d& p = view.board_points[i];
      sse += (ProjectBoardPoint(camera, cam_from_board[v], p) - view.image_points[i]).squaredNorm();
      for (int k = 0; k < intrinsics; ++k) {
        Eigen::Matrix<double, 5, 1> plus = x0, minus = x0;
        plus(k) += steps(k);
        minus(k) -= steps(k);
        jacobian.block<2, 1>(row, k) =
            (ProjectBoardPoint(WithIntrinsics(camera, plus), cam_from_board[v], p) -
             ProjectBoardPoint(WithIntrinsics(camera, minus), cam_from_board[v], p)) /
            (2.0 * steps(k));
      }
      for (int k = 0; k < 6; ++k) {
        const int col = intrinsics + 6 * static_cast<int>(v) + k;
        jacobian.block<2, 1>(row, col) =
            (ProjectBoardPoint(camera, Perturbed(cam_from_board[v], k, kPoseStep), p) -
             ProjectBoardPoint(camera, Perturbed(cam_from_board[v], k, -kPoseStep), p)) /
            (2.0 * kPoseStep);
      }
    }
  }
  const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(normal);
  if (ldlt.info() != Eigen::Success) return std_dev;
  const Eigen::MatrixXd covariance =
      ldlt.solve(Eigen::MatrixXd::Identity(params, params)) * (sse / (residuals - params));
  for (int k = 0; k < intrinsics; ++k) {
    const double variance = covariance(k, k);
    if (!(variance >= 0.0) || !std::isfinite(variance)) return Eigen::Matrix<double, 5, 1>::Zero();
    std_dev(k) = std::sqrt(variance);
  }
  return std_dev;
}

}  // namespace linetrack
