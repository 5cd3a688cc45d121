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

// Pose moved by a rotation vector w (applied on the left: R' = exp(w) R) and t' = t + dt,
// step = (w, dt).
Eigen::Isometry3d PoseStep(const Eigen::Isometry3d& pose, const Eigen::Matrix<double, 6, 1>& step) {
  Eigen::Isometry3d out = pose;
  const Eigen::Vector3d w = step.head<3>();
  if (w.norm() > 0.0) {
    out.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() * pose.linear();
  }
  out.translation() += step.tail<3>();
  return out;
}

// All residuals (projection - measurement, u then v, view by view).
Eigen::VectorXd Residuals(const std::vector<BoardView>& views, const CameraIntrinsics& camera,
                          const std::vector<Eigen::Isometry3d>& cam_from_board) {
  int n = 0;
  for (const BoardView& v : views)
    n += 2 * static_cast<int>(v.board_points.size());
  Eigen::VectorXd r(n);
  int row = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    for (size_t i = 0; i < views[v].board_points.size(); ++i, row += 2) {
      r.segment<2>(row) = ProjectBoardPoint(camera, cam_from_board[v], views[v].board_points[i]) -
                          views[v].image_points[i];
    }
  }
  return r;
}

// Residuals and their central-difference Jacobian over (px, py, u0, v0, kud) then 6 parameters
// per pose (PoseStep). False when there are no more residuals than parameters.
bool ResidualsAndJacobian(const std::vector<BoardView>& views, const CameraIntrinsics& camera,
                          const std::vector<Eigen::Isometry3d>& cam_from_board,
                          Eigen::VectorXd* residual, Eigen::MatrixXd* jacobian) {
  constexpr int kIntrinsics = 5;
  const int params = kIntrinsics + 6 * static_cast<int>(views.size());
  *residual = Residuals(views, camera, cam_from_board);
  if (residual->size() <= params) return false;
  jacobian->setZero(residual->size(), params);
  const Eigen::Matrix<double, 5, 1> x0 = IntrinsicVector(camera);
  const Eigen::Matrix<double, 5, 1> steps(1e-4 * camera.px, 1e-4 * camera.py, 1e-3, 1e-3, 1e-6);
  constexpr double kPoseStep = 1e-6;  // radians and metres
  int row = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    for (size_t i = 0; i < views[v].board_points.size(); ++i, row += 2) {
      const Eigen::Vector3d& p = views[v].board_points[i];
      for (int k = 0; k < kIntrinsics; ++k) {
        Eigen::Matrix<double, 5, 1> plus = x0, minus = x0;
        plus(k) += steps(k);
        minus(k) -= steps(k);
        jacobian->block<2, 1>(row, k) =
            (ProjectBoardPoint(WithIntrinsics(camera, plus), cam_from_board[v], p) -
             ProjectBoardPoint(WithIntrinsics(camera, minus), cam_from_board[v], p)) /
            (2.0 * steps(k));
      }
      for (int k = 0; k < 6; ++k) {
        Eigen::Matrix<double, 6, 1> step = Eigen::Matrix<double, 6, 1>::Zero();
        step(k) = kPoseStep;
        jacobian->block<2, 1>(row, kIntrinsics + 6 * static_cast<int>(v) + k) =
            (ProjectBoardPoint(camera, PoseStep(cam_from_board[v], step), p) -
             ProjectBoardPoint(camera, PoseStep(cam_from_board[v], -step), p)) /
            (2.0 * kPoseStep);
      }
    }
  }
  return true;
}

}  // namespace

bool VispCalibrationOptions::Check(std::string* why) const {
  if (!(gain > 0.0 && gain <= 1.0)) {
    *why = "ViSP calibration gain must be within (0, 1]";
    return false;
  }
  if (refine_iterations < 1) {
    *why = "refinement needs at least one iteration";
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
      calib.clearPoint();
      for (size_t i = 0; i < view.board_points.size(); ++i) {
        const Eigen::Vector3d& p = view.board_points[i];
        vpImagePoint ip(view.image_points[i].y(), view.image_points[i].x());
        calib.addPoint(p.x(), p.y(), p.z(), ip);
      }
      vpHomogeneousMatrix cMo;
      if (calib.computeCalibration(vpCalibration::CALIB_VIRTUAL_VS, cMo, cam, /*verbose=*/false) !=
          0) {
        result.failure = "ViSP could not calibrate view " + view.name + " alone";
        return result;
      }
      calibrators.push_back(calib);
    }
    double error = 0.0;
    if (vpCalibration::computeCalibrationMulti(vpCalibration::CALIB_VIRTUAL_VS, calibrators, cam,
                                               error, /*verbose=*/false) != 0) {
      result.failure = "ViSP calibration without distortion failed";
      return result;
    }
    result.without = FromVisp(cam, width, height, /*distorted=*/false);
    result.global_error_without = error;
    if (vpCalibration::computeCalibrationMulti(vpCalibration::CALIB_VIRTUAL_VS_DIST, calibrators,
                                               cam, error, /*verbose=*/false) != 0) {
      result.failure = "ViSP calibration with distortion failed";
      return result;
    }
    result.with = FromVisp(cam, width, height, /*distorted=*/true);
    result.global_error_with = error;
    std::vector<Eigen::Isometry3d> poses_without;
    for (const vpCalibration& c : calibrators) {
      poses_without.push_back(ToIsometry(c.cMo));
      result.cam_from_board_final.push_back(ToIsometry(c.cMo_dist));
    }
    result.view_error_without = ViewErrors(views, result.without, poses_without);
    result.view_error_with = ViewErrors(views, result.with, result.cam_from_board_final);
  } catch (const vpException& e) {
    result.failure = std::string("ViSP calibration failed: ") + e.getMessage();
    return result;
  }
  if (!AllFinite(result.without) || !AllFinite(result.with) ||
      !std::isfinite(result.global_error_with)) {
    result.failure = "ViSP calibration diverged (non-finite or non-positive focal length)";
    return result;
  }
  result.final_model = result.with;
  if (options.refine) {
    result.refined = RefineVispModel(views, options.refine_iterations, &result.final_model,
                                     &result.cam_from_board_final);
    if (result.refined) result.final_model.kdu = FitKdu(result.final_model);
  }
  result.view_error_final = ViewErrors(views, result.final_model, result.cam_from_board_final);
  std::vector<int> counts;
  for (const BoardView& v : views)
    counts.push_back(static_cast<int>(v.board_points.size()));
  result.rms_final = PooledRms(result.view_error_final, counts);
  result.std_dev = VispModelStdDev(views, result.final_model, result.cam_from_board_final);
  result.ok = true;
  return result;
}

bool RefineVispModel(const std::vector<BoardView>& views, int iterations, CameraIntrinsics* camera,
                     std::vector<Eigen::Isometry3d>* cam_from_board) {
  Eigen::MatrixXd jacobian;
  Eigen::VectorXd residual;
  if (!ResidualsAndJacobian(views, *camera, *cam_from_board, &residual, &jacobian)) return false;
  double cost = residual.squaredNorm(), lambda = 1e-3;
  bool improved = false;
  for (int it = 0; it < iterations; ++it) {
    const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
    const Eigen::VectorXd gradient = jacobian.transpose() * residual;
    bool accepted = false;
    while (!accepted && lambda < 1e10) {
      Eigen::MatrixXd damped = normal;
      damped.diagonal() += lambda * normal.diagonal();
      const Eigen::VectorXd step = damped.ldlt().solve(-gradient);
      const CameraIntrinsics trial_camera =
          WithIntrinsics(*camera, IntrinsicVector(*camera) + step.head<5>());
      std::vector<Eigen::Isometry3d> trial_poses = *cam_from_board;
      for (size_t v = 0; v < trial_poses.size(); ++v)
        trial_poses[v] = PoseStep(trial_poses[v], step.segment<6>(5 + 6 * static_cast<int>(v)));
      Eigen::VectorXd trial_residual = Residuals(views, trial_camera, trial_poses);
      const double trial_cost = trial_residual.squaredNorm();
      if (std::isfinite(trial_cost) && trial_cost < cost) {
        accepted = improved = true;
        const double relative = (cost - trial_cost) / cost;
        *camera = trial_camera;
        *cam_from_board = trial_poses;
        cost = trial_cost;
        lambda = std::max(lambda * 0.1, 1e-12);
        if (relative < 1e-12) return true;
        ResidualsAndJacobian(views, *camera, *cam_from_board, &residual, &jacobian);
      } else {
        lambda *= 10.0;
      }
    }
    if (!accepted) break;
  }
  return improved;
}

double FitKdu(const CameraIntrinsics& camera) {
  constexpr int kGrid = 40;
  double numerator = 0.0, denominator = 0.0;
  for (int a = 0; a <= kGrid; ++a) {
    for (int b = 0; b <= kGrid; ++b) {
      const Eigen::Vector2d d((camera.width * a / double(kGrid) - camera.u0) / camera.px,
                              (camera.height * b / double(kGrid) - camera.v0) / camera.py);
      // Exact undistorted point of d: solve d = x (1 + kud |x|^2) by fixed-point iteration.
      Eigen::Vector2d x = d;
      for (int k = 0; k < 50; ++k)
        x = d / (1.0 + camera.kud * x.squaredNorm());
      const Eigen::Vector2d basis = d * d.squaredNorm();
      numerator += basis.dot(x - d);
      denominator += basis.squaredNorm();
    }
  }
  return denominator > 0.0 ? numerator / denominator : 0.0;
}

Eigen::Matrix<double, 5, 1> VispModelStdDev(const std::vector<BoardView>& views,
                                            const CameraIntrinsics& camera,
                                            const std::vector<Eigen::Isometry3d>& cam_from_board) {
  Eigen::Matrix<double, 5, 1> std_dev = Eigen::Matrix<double, 5, 1>::Zero();
  Eigen::MatrixXd jacobian;
  Eigen::VectorXd residual;
  if (!ResidualsAndJacobian(views, camera, cam_from_board, &residual, &jacobian)) return std_dev;
  const int residuals = static_cast<int>(jacobian.rows()),
            params = static_cast<int>(jacobian.cols());
  const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(normal);
  if (ldlt.info() != Eigen::Success) return std_dev;
  const Eigen::MatrixXd covariance = ldlt.solve(Eigen::MatrixXd::Identity(params, params)) *
                                     (residual.squaredNorm() / (residuals - params));
  for (int k = 0; k < 5; ++k) {
    const double variance = covariance(k, k);
    if (!(variance >= 0.0) || !std::isfinite(variance)) return Eigen::Matrix<double, 5, 1>::Zero();
    std_dev(k) = std::sqrt(variance);
  }
  return std_dev;
}

}  // namespace linetrack
