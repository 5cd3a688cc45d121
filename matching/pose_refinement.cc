#include "matching/pose_refinement.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "matching/constraints.h"

namespace linetrack {

bool PoseRefinementOptions::Check(std::string* why) const {
  if (max_iterations < 1 || !(step_tolerance > 0.0) || !(huber_px >= 0.0)) {
    *why = "pose refinement: max_iterations >= 1, step_tolerance > 0, huber_px >= 0";
    return false;
  }
  return true;
}

Eigen::Vector2d EndpointResiduals(const LineMatch& match, const CameraIntrinsics& camera,
                                  double height, double tilt, const Pose3Dof& pose,
                                  Eigen::Matrix<double, 2, 3>* jacobian) {
  const Eigen::Matrix3d cam_from_level = LevelFromCam(tilt).transpose();
  const double ch = std::cos(pose.heading), sh = std::sin(pose.heading);
  Eigen::Matrix3d level_from_world, d_level_from_world;
  level_from_world << sh, -ch, 0.0, 0.0, 0.0, -1.0, ch, sh, 0.0;
  d_level_from_world << ch, sh, 0.0, 0.0, 0.0, 0.0, -sh, ch, 0.0;
  const Eigen::Matrix3d rotation = cam_from_level * level_from_world;
  const Eigen::Vector3d centre(pose.x, pose.y, height);
  const Eigen::Vector3d xa = rotation * (match.edge_a - centre);
  const Eigen::Vector3d xb = rotation * (match.edge_b - centre);
  // Line through the two projections in normalised coordinates, then in pixels: l_p = K^-T l_n.
  const Eigen::Vector3d ln = xa.cross(xb);
  auto to_pixels = [&](const Eigen::Vector3d& l) {
    return Eigen::Vector3d(l.x() / camera.px, l.y() / camera.py,
                           l.z() - l.x() * camera.u0 / camera.px - l.y() * camera.v0 / camera.py);
  };
  const Eigen::Vector3d lp = to_pixels(ln);
  const double norm = std::hypot(lp.x(), lp.y());
  const Eigen::Vector3d qa(match.observed.a.x(), match.observed.a.y(), 1.0);
  const Eigen::Vector3d qb(match.observed.b.x(), match.observed.b.y(), 1.0);
  const Eigen::Vector2d r(lp.dot(qa) / norm, lp.dot(qb) / norm);
  if (jacobian) {
    Eigen::Matrix3d dxa, dxb;  // columns: d/dh, d/dx, d/dy
    const Eigen::Matrix3d d_rotation = cam_from_level * d_level_from_world;
    dxa.col(0) = d_rotation * (match.edge_a - centre);
    dxb.col(0) = d_rotation * (match.edge_b - centre);
    dxa.col(1) = dxb.col(1) = -rotation.col(0);
    dxa.col(2) = dxb.col(2) = -rotation.col(1);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d dlp = to_pixels(dxa.col(k).cross(xb) + xa.cross(dxb.col(k)));
      const double dnorm = (lp.x() * dlp.x() + lp.y() * dlp.y()) / norm;
      (*jacobian)(0, k) = (dlp.dot(qa) * norm - lp.dot(qa) * dnorm) / (norm * norm);
      (*jacobian)(1, k) = (dlp.dot(qb) * norm - lp.dot(qb) * dnorm) / (norm * norm);
    }
  }
  return r;
}

namespace {

CameraIntrinsics Scaled(const CameraIntrinsics& camera, double scale) {
  CameraIntrinsics c = camera;
  c.px *= scale;
  c.py *= scale;
  return c;
}

}  // namespace

PoseRefinementResult RefinePose(const std::vector<LineMatch>& matches,
                                const CameraIntrinsics& camera, double height, double tilt,
                                const Pose3Dof& start, const PoseRefinementOptions& options) {
  return RefinePose(matches, camera, height, tilt, start, 1.0, options);
}

PoseRefinementResult RefinePose(const std::vector<LineMatch>& matches,
                                const CameraIntrinsics& camera, double height, double tilt,
                                const Pose3Dof& start, double start_scale,
                                const PoseRefinementOptions& options) {
  PoseRefinementResult result;
  result.pose = start;
  result.focal_scale = start_scale;
  if (matches.empty()) return result;
  const int n = static_cast<int>(matches.size());
  // Parameters: (heading, x, y) and, with enough lines and a prior, the focal scale s, which
  // absorbs a calibration error (MAP with s ~ N(1, focal_prior_sigma), the prior weighed as one
  // residual of prior_pixel_sigma pixels).
  const bool with_scale = options.focal_prior_sigma > 0.0 && n >= options.min_matches_for_scale;
  const int dof = with_scale ? 4 : 3;
  const double prior_weight =
      with_scale ? options.prior_pixel_sigma / options.focal_prior_sigma : 0.0;
  auto huber = [&](double r) {
    const double a = std::abs(r);
    return options.huber_px > 0.0 && a > options.huber_px
               ? options.huber_px * (2.0 * a - options.huber_px)
               : a * a;
  };
  auto weight = [&](double r) {
    const double a = std::abs(r);
    return options.huber_px > 0.0 && a > options.huber_px ? options.huber_px / a : 1.0;
  };
  auto cost_at = [&](const Pose3Dof& pose, double scale) {
    const CameraIntrinsics c = Scaled(camera, scale);
    double cost = 0.0;
    for (const LineMatch& m : matches) {
      const Eigen::Vector2d r = EndpointResiduals(m, c, height, tilt, pose);
      cost += huber(r[0]) + huber(r[1]);
    }
    const double p = prior_weight * (scale - 1.0);
    return cost + p * p;
  };
  // Normal equations at (pose, scale); the scale column by central differences.
  auto normal_equations = [&](const Pose3Dof& pose, double scale, bool robust, Eigen::Matrix4d* jtj,
                              Eigen::Vector4d* jtr) {
    jtj->setZero();
    jtr->setZero();
    const CameraIntrinsics c = Scaled(camera, scale);
    const double h = 1e-6;
    const CameraIntrinsics up = Scaled(camera, scale + h), down = Scaled(camera, scale - h);
    double squares = 0.0;
    for (const LineMatch& m : matches) {
      Eigen::Matrix<double, 2, 3> j3;
      const Eigen::Vector2d r = EndpointResiduals(m, c, height, tilt, pose, &j3);
      squares += r.squaredNorm();
      Eigen::Matrix<double, 2, 4> j = Eigen::Matrix<double, 2, 4>::Zero();
      j.leftCols<3>() = j3;
      if (with_scale) {
        j.col(3) = (EndpointResiduals(m, up, height, tilt, pose) -
                    EndpointResiduals(m, down, height, tilt, pose)) /
                   (2.0 * h);
      }
      for (int k = 0; k < 2; ++k) {
        const double w = robust ? weight(r[k]) : 1.0;
        *jtj += w * j.row(k).transpose() * j.row(k);
        *jtr += w * j.row(k).transpose() * r[k];
      }
    }
    if (with_scale) {
      (*jtj)(3, 3) += prior_weight * prior_weight;
      (*jtr)(3) += prior_weight * prior_weight * (scale - 1.0);
    }
    return squares;
  };

  double lambda = 1e-3;
  double cost = cost_at(result.pose, result.focal_scale);
  Eigen::Matrix4d jtj;
  Eigen::Vector4d jtr;
  for (int it = 0; it < options.max_iterations; ++it) {
    result.iterations = it + 1;
    normal_equations(result.pose, result.focal_scale, true, &jtj, &jtr);
    bool improved = false;
    Eigen::Vector4d step = Eigen::Vector4d::Zero();
    for (int attempt = 0; attempt < 8 && !improved; ++attempt) {
      Eigen::MatrixXd damped = jtj.topLeftCorner(dof, dof);
      damped.diagonal() *= 1.0 + lambda;
      damped.diagonal().array() += 1e-12;
      step.head(dof) = -damped.ldlt().solve(jtr.head(dof));
      const Pose3Dof trial{result.pose.x + step[1], result.pose.y + step[2],
                           result.pose.heading + step[0]};
      const double trial_scale = result.focal_scale + step[3];
      const double trial_cost = cost_at(trial, trial_scale);
      if (std::isfinite(trial_cost) && trial_cost <= cost && trial_scale > 0.5) {
        result.pose = trial;
        result.focal_scale = trial_scale;
        cost = trial_cost;
        lambda = std::max(lambda * 0.3, 1e-9);
        improved = true;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved || step.norm() < options.step_tolerance) {
      result.converged = improved || step.norm() < options.step_tolerance;
      break;
    }
  }
  result.pose.heading = WrapAngle(result.pose.heading);
  const double squares = normal_equations(result.pose, result.focal_scale, false, &jtj, &jtr);
  result.rms_px = std::sqrt(squares / (2.0 * n));
  // Pose uncertainty for 1 pixel of noise (the scale, when estimated, is marginalised out).
  const Eigen::MatrixXd information = jtj.topLeftCorner(dof, dof);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(information);
  const Eigen::MatrixXd covariance = ldlt.solve(Eigen::MatrixXd::Identity(dof, dof));
  if (ldlt.info() == Eigen::Success && covariance.allFinite() && covariance(0, 0) >= 0.0) {
    result.heading_sigma_rad = std::sqrt(covariance(0, 0));
    const Eigen::Matrix2d position = covariance.block<2, 2>(1, 1);
    result.position_sigma_m = std::sqrt(std::max(
        0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(position, Eigen::EigenvaluesOnly)
                 .eigenvalues()[1]));
  } else {
    result.heading_sigma_rad = result.position_sigma_m = std::numeric_limits<double>::infinity();
  }
  return result;
}

}  // namespace linetrack
