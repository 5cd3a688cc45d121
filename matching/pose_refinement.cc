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

PoseRefinementResult RefinePose(const std::vector<LineMatch>& matches,
                                const CameraIntrinsics& camera, double height, double tilt,
                                const Pose3Dof& start, const PoseRefinementOptions& options) {
  PoseRefinementResult result;
  result.pose = start;
  if (matches.empty()) return result;
  const int n = static_cast<int>(matches.size());
  auto weight = [&](double r) {
    const double a = std::abs(r);
    return options.huber_px > 0.0 && a > options.huber_px ? options.huber_px / a : 1.0;
  };
  auto cost_at = [&](const Pose3Dof& pose) {
    double cost = 0.0;
    for (const LineMatch& m : matches) {
      const Eigen::Vector2d r = EndpointResiduals(m, camera, height, tilt, pose);
      for (int k = 0; k < 2; ++k) {
        const double a = std::abs(r[k]);
        cost += options.huber_px > 0.0 && a > options.huber_px
                    ? options.huber_px * (2.0 * a - options.huber_px)
                    : a * a;
      }
    }
    return cost;
  };

  double lambda = 1e-3;
  double cost = cost_at(result.pose);
  Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
  for (int it = 0; it < options.max_iterations; ++it) {
    result.iterations = it + 1;
    jtj.setZero();
    Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
    for (const LineMatch& m : matches) {
      Eigen::Matrix<double, 2, 3> j;
      const Eigen::Vector2d r = EndpointResiduals(m, camera, height, tilt, result.pose, &j);
      for (int k = 0; k < 2; ++k) {
        const double w = weight(r[k]);
        jtj += w * j.row(k).transpose() * j.row(k);
        jtr += w * j.row(k).transpose() * r[k];
      }
    }
    bool improved = false;
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    for (int attempt = 0; attempt < 8 && !improved; ++attempt) {
      Eigen::Matrix3d damped = jtj;
      damped.diagonal() *= 1.0 + lambda;
      damped.diagonal().array() += 1e-12;
      step = -damped.ldlt().solve(jtr);
      const Pose3Dof trial{result.pose.x + step[1], result.pose.y + step[2],
                           result.pose.heading + step[0]};
      const double trial_cost = cost_at(trial);
      if (std::isfinite(trial_cost) && trial_cost <= cost) {
        result.pose = trial;
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
  double squares = 0.0;
  jtj.setZero();
  for (const LineMatch& m : matches) {
    Eigen::Matrix<double, 2, 3> j;
    squares += EndpointResiduals(m, camera, height, tilt, result.pose, &j).squaredNorm();
    jtj += j.transpose() * j;
  }
  result.rms_px = std::sqrt(squares / (2.0 * n));
  const Eigen::LDLT<Eigen::Matrix3d> information(jtj);
  const Eigen::Matrix3d covariance = information.solve(Eigen::Matrix3d::Identity());
  if (information.info() == Eigen::Success && covariance.allFinite() && covariance(0, 0) >= 0.0) {
    result.heading_sigma_rad = std::sqrt(covariance(0, 0));
    result.position_sigma_m =
        std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(
                                    covariance.block<2, 2>(1, 1), Eigen::EigenvaluesOnly)
                                    .eigenvalues()[1]));
  } else {
    result.heading_sigma_rad = result.position_sigma_m = std::numeric_limits<double>::infinity();
  }
  return result;
}

}  // namespace linetrack
