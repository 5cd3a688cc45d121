#include "matching/pose_refinement.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <utility>

#include "matching/constraints.h"

namespace linetrack {

bool PoseRefinementOptions::Check(std::string* why) const {
  if (max_iterations < 1 || !(step_tolerance > 0.0) || !(huber_px >= 0.0)) {
    *why = "pose refinement: max_iterations >= 1, step_tolerance > 0, huber_px >= 0";
    return false;
  }
  if (bounds.active &&
      !(bounds.radius_m >= 0.0 && bounds.half_width_rad >= 0.0 && bounds.sigmas >= 0.0 &&
        bounds.softness_m > 0.0 && bounds.softness_rad > 0.0 && bounds.centre.allFinite() &&
        std::isfinite(bounds.heading))) {
    *why = "pose refinement: bounds need radius, half width, sigmas >= 0 and softness > 0";
    return false;
  }
  return true;
}

Eigen::Vector2d EndpointResiduals(const LineMatch& match, const CameraIntrinsics& camera,
                                  double height, double tilt, const Pose3Dof& pose,
                                  Eigen::Matrix<double, 2, 3>* jacobian) {
  if (jacobian == nullptr)
    return EndpointResiduals(match, camera, height, tilt, pose, 1.0, nullptr);
  Eigen::Matrix<double, 2, 4> j4;
  const Eigen::Vector2d r = EndpointResiduals(match, camera, height, tilt, pose, 1.0, &j4);
  *jacobian = j4.leftCols<3>();
  return r;
}

PoseView ViewOf(const Pose3Dof& pose, double height, double tilt) {
  const Eigen::Matrix3d cam_from_level = LevelFromCam(tilt).transpose();
  const double ch = std::cos(pose.heading), sh = std::sin(pose.heading);
  Eigen::Matrix3d level_from_world, d_level_from_world;
  level_from_world << sh, -ch, 0.0, 0.0, 0.0, -1.0, ch, sh, 0.0;
  d_level_from_world << ch, sh, 0.0, 0.0, 0.0, 0.0, -sh, ch, 0.0;
  return {cam_from_level * level_from_world, cam_from_level * d_level_from_world,
          Eigen::Vector3d(pose.x, pose.y, height)};
}

Eigen::Vector3d ProjectedEdgeLine(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const CameraIntrinsics& camera, double height, double tilt,
                                  const Pose3Dof& pose, double scale,
                                  Eigen::Matrix<double, 3, 4>* derivative) {
  return ProjectedEdgeLine(a, b, camera, ViewOf(pose, height, tilt), scale, derivative);
}

Eigen::Vector3d ProjectedEdgeLine(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const CameraIntrinsics& camera, const PoseView& view,
                                  double scale, Eigen::Matrix<double, 3, 4>* derivative) {
  const Eigen::Vector3d xa = view.rotation * (a - view.centre);
  const Eigen::Vector3d xb = view.rotation * (b - view.centre);
  // Line through the two projections in normalised coordinates, then in pixels: l_p = K^-T l_n,
  // K with focal lengths s px, s py; then scaled to a unit normal.
  const Eigen::Vector3d ln = xa.cross(xb);
  const double inv_fx = 1.0 / (scale * camera.px), inv_fy = 1.0 / (scale * camera.py);
  auto to_pixels = [&](const Eigen::Vector3d& l) {
    const double p = l.x() * inv_fx, q = l.y() * inv_fy;
    return Eigen::Vector3d(p, q, l.z() - p * camera.u0 - q * camera.v0);
  };
  const Eigen::Vector3d lp = to_pixels(ln);
  const double inv_norm = 1.0 / std::sqrt(lp.x() * lp.x() + lp.y() * lp.y());
  const Eigen::Vector3d line = lp * inv_norm;
  if (derivative) {
    // d (lp / |lp_uv|) = (dlp - line (line_uv . dlp_uv)) / |lp_uv|.
    auto column = [&](const Eigen::Vector3d& dlp, int k) {
      derivative->col(k) = (dlp - line * (line.x() * dlp.x() + line.y() * dlp.y())) * inv_norm;
    };
    column(to_pixels((view.d_rotation * (a - view.centre)).cross(xb) +
                     xa.cross(view.d_rotation * (b - view.centre))),
           0);
    // d x_a / dx = d x_b / dx = d = -rotation.col(0) (y likewise): d ln = d x (xb - xa).
    const Eigen::Vector3d along = xb - xa;
    for (int k = 1; k <= 2; ++k)
      column(to_pixels(along.cross(view.rotation.col(k - 1))), k);
    // lp(s) = (p / s, q / s, l_z - (p u0 + q v0) / s): d lp / ds = -(lp - (0, 0, l_z)) / s.
    column(-(lp - Eigen::Vector3d(0.0, 0.0, ln.z())) / scale, 3);
  }
  return line;
}

Eigen::Vector2d EndpointResiduals(const LineMatch& match, const CameraIntrinsics& camera,
                                  double height, double tilt, const Pose3Dof& pose, double scale,
                                  Eigen::Matrix<double, 2, 4>* jacobian) {
  return EndpointResiduals(match, camera, ViewOf(pose, height, tilt), scale, jacobian);
}

Eigen::Vector2d EndpointResiduals(const LineMatch& match, const CameraIntrinsics& camera,
                                  const PoseView& view, double scale,
                                  Eigen::Matrix<double, 2, 4>* jacobian) {
  Eigen::Matrix<double, 3, 4> d;
  const Eigen::Vector3d line =
      ProjectedEdgeLine(match.edge_a, match.edge_b, camera, view, scale, jacobian ? &d : nullptr);
  const Eigen::Vector3d qa(match.observed.a.x(), match.observed.a.y(), 1.0);
  const Eigen::Vector3d qb(match.observed.b.x(), match.observed.b.y(), 1.0);
  if (jacobian) {
    jacobian->row(0) = qa.transpose() * d;
    jacobian->row(1) = qb.transpose() * d;
  }
  return {line.dot(qa), line.dot(qb)};
}

PoseRefinementResult RefinePose(const std::vector<LineMatch>& matches,
                                const CameraIntrinsics& camera, double height, double tilt,
                                const Pose3Dof& start, const PoseRefinementOptions& options) {
  return RefinePose(matches, camera, height, tilt, start, 1.0, options);
}

namespace {

// Covariance of (heading, x, y[, scale]) from the information's dof x dof block, with the
// position's largest standard deviation and the heading's; false when it is singular.
bool UncertaintyOf(const Eigen::Matrix4d& jtj, int dof, Eigen::Matrix4d* covariance_out,
                   double* position_sigma, double* heading_sigma) {
  const Eigen::MatrixXd information = jtj.topLeftCorner(dof, dof);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(information);
  const Eigen::MatrixXd covariance = ldlt.solve(Eigen::MatrixXd::Identity(dof, dof));
  if (!(ldlt.info() == Eigen::Success && covariance.allFinite() && covariance(0, 0) >= 0.0 &&
        covariance(1, 1) >= 0.0 && covariance(2, 2) >= 0.0)) {
    covariance_out->setConstant(std::numeric_limits<double>::infinity());
    *heading_sigma = *position_sigma = std::numeric_limits<double>::infinity();
    return false;
  }
  covariance_out->setZero();
  covariance_out->topLeftCorner(dof, dof) = covariance;
  *heading_sigma = std::sqrt(covariance(0, 0));
  *position_sigma = LargestPositionSigma(covariance.block<2, 2>(1, 1));
  return true;
}

// UncertaintyOf's two standard deviations (position's largest, heading) at fixed size, for the
// bounds' border during the iterations (infinite when the information is singular).
std::pair<double, double> SigmasOf(const Eigen::Matrix4d& jtj, int dof) {
  Eigen::Matrix3d position_heading;  // covariance of (heading, x, y)
  bool ok = false;
  if (dof == 4) {
    const Eigen::LDLT<Eigen::Matrix4d> ldlt(jtj);
    const Eigen::Matrix4d c = ldlt.solve(Eigen::Matrix4d::Identity());
    ok = ldlt.info() == Eigen::Success;
    position_heading = c.topLeftCorner<3, 3>();
  } else {
    const Eigen::Matrix3d information = jtj.topLeftCorner<3, 3>();
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(information);
    position_heading = ldlt.solve(Eigen::Matrix3d::Identity());
    ok = ldlt.info() == Eigen::Success;
  }
  const double a = position_heading(1, 1), b = position_heading(1, 2), c = position_heading(2, 2);
  if (!ok || !position_heading.allFinite() || !(position_heading(0, 0) >= 0.0) || !(a >= 0.0) ||
      !(c >= 0.0)) {
    return {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  }
  // Largest eigenvalue of the 2x2 position block.
  const double largest = 0.5 * (a + c) + std::sqrt(0.25 * (a - c) * (a - c) + b * b);
  return {std::sqrt(std::max(0.0, largest)), std::sqrt(position_heading(0, 0))};
}

// The bounds' widening for a standard deviation (infinite for an unobservable direction).
double Widening(const PoseBounds& bounds, double sigma) {
  return bounds.sigmas > 0.0 ? bounds.sigmas * sigma : 0.0;
}

}  // namespace

double LargestPositionSigma(const Eigen::Matrix2d& position_covariance) {
  return std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(
                                     position_covariance, Eigen::EigenvaluesOnly)
                                     .eigenvalues()[1]));
}

Eigen::Vector2d BoundsResiduals(const PoseBounds& bounds, const Pose3Dof& pose, double radius_m,
                                double half_width_rad, Eigen::Matrix<double, 2, 3>* jacobian) {
  const Eigen::Vector2d offset(pose.x - bounds.centre.x(), pose.y - bounds.centre.y());
  const double distance = offset.norm();
  const double turn = WrapAngle(pose.heading - bounds.heading);
  const Eigen::Vector2d r(std::max(0.0, distance - radius_m) / bounds.softness_m,
                          std::max(0.0, std::abs(turn) - half_width_rad) / bounds.softness_rad);
  if (jacobian != nullptr) {
    jacobian->setZero();
    // d |p - c| / d p = (p - c) / |p - c|; d |turn| / d heading = sign(turn).
    if (r[0] > 0.0)
      jacobian->block<1, 2>(0, 1) = offset.transpose() / (distance * bounds.softness_m);
    if (r[1] > 0.0) (*jacobian)(1, 0) = (turn > 0.0 ? 1.0 : -1.0) / bounds.softness_rad;
  }
  return r;
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
  // Parameters (heading, x, y) and, with enough lines, the focal scale s, which absorbs a
  // calibration error: MAP with the prior s ~ N(1, focal_prior_sigma).
  const bool with_scale = options.focal_prior_sigma > 0.0 && n >= options.min_matches_for_scale;
  const int dof = with_scale ? 4 : 3;
  const double prior_weight = with_scale ? 1.0 / options.focal_prior_sigma : 0.0;
  const PoseBounds& bounds = options.bounds;
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
  // One pass over the pairs at (pose, scale): the normal equations of the whitened residuals,
  // Huber-weighted when `robust`, in (jtj, jtr); optionally those of the other weighting in
  // (other_jtj, other_jtr) and the Huber cost in *huber_cost. Returns the raw sum of squared pixel
  // residuals and (in *chi2) of the whitened ones.
  auto normal_equations = [&](const Pose3Dof& pose, double scale, bool robust, Eigen::Matrix4d* jtj,
                              Eigen::Vector4d* jtr, double* chi2,
                              Eigen::Matrix4d* other_jtj = nullptr,
                              Eigen::Vector4d* other_jtr = nullptr, double* huber_cost = nullptr) {
    jtj->setZero();
    jtr->setZero();
    if (other_jtj != nullptr) {
      other_jtj->setZero();
      other_jtr->setZero();
    }
    if (huber_cost != nullptr) *huber_cost = 0.0;
    double squares = 0.0;
    *chi2 = 0.0;
    const PoseView view = ViewOf(pose, height, tilt);
    for (const LineMatch& m : matches) {
      Eigen::Matrix<double, 2, 4> j;
      const Eigen::Vector2d raw = EndpointResiduals(m, camera, view, scale, &j);
      squares += raw.squaredNorm();
      const Eigen::Vector2d r = m.whitening * raw;
      *chi2 += r.squaredNorm();
      if (huber_cost != nullptr) *huber_cost += huber(r[0]) + huber(r[1]);
      j = m.whitening * j;
      if (!with_scale) j.col(3).setZero();
      for (int k = 0; k < 2; ++k) {
        const double w = robust ? weight(r[k]) : 1.0;
        *jtj += w * j.row(k).transpose() * j.row(k);
        *jtr += w * j.row(k).transpose() * r[k];
        if (other_jtj != nullptr) {
          const double v = robust ? 1.0 : weight(r[k]);
          *other_jtj += v * j.row(k).transpose() * j.row(k);
          *other_jtr += v * j.row(k).transpose() * r[k];
        }
      }
    }
    if (with_scale) {
      (*jtj)(3, 3) += prior_weight * prior_weight;
      (*jtr)(3) += prior_weight * prior_weight * (scale - 1.0);
      if (other_jtj != nullptr) {
        (*other_jtj)(3, 3) += prior_weight * prior_weight;
        (*other_jtr)(3) += prior_weight * prior_weight * (scale - 1.0);
      }
    }
    return squares;
  };
  // The bounds' border, widened by the image evidence's sigmas from the plain information
  // `plain_jtj` at a pose; only used when the pose leaves the unwidened region (else no residual).
  auto outside_unwidened = [&](const Pose3Dof& pose) {
    return bounds.active &&
           (std::hypot(pose.x - bounds.centre.x(), pose.y - bounds.centre.y()) > bounds.radius_m ||
            std::abs(WrapAngle(pose.heading - bounds.heading)) > bounds.half_width_rad);
  };
  auto border_of = [&](const Eigen::Matrix4d& plain_jtj) {
    const auto [position_sigma, heading_sigma] = SigmasOf(plain_jtj, dof);
    return std::make_pair(bounds.radius_m + Widening(bounds, position_sigma),
                          bounds.half_width_rad + Widening(bounds, heading_sigma));
  };
  // The border of the current step: widened by the sigmas of the image evidence at the iterate,
  // held fixed during the step's trials as the bounds' Jacobian holds them (the trials then need
  // the residuals only). Computed when first needed in a step (most refinements stay inside).
  std::pair<double, double> border{bounds.radius_m, bounds.half_width_rad};
  bool border_ready = false;
  auto step_border = [&]() {
    if (!border_ready) {
      Eigen::Matrix4d plain_jtj;
      Eigen::Vector4d plain_jtr;
      double plain_chi2 = 0.0;
      normal_equations(result.pose, result.focal_scale, false, &plain_jtj, &plain_jtr, &plain_chi2);
      border = border_of(plain_jtj);
      border_ready = true;
    }
    return border;
  };
  auto cost_at = [&](const Pose3Dof& pose, double scale) {
    double cost = 0.0;
    const PoseView view = ViewOf(pose, height, tilt);
    for (const LineMatch& m : matches) {
      const Eigen::Vector2d r = m.whitening * EndpointResiduals(m, camera, view, scale, nullptr);
      cost += huber(r[0]) + huber(r[1]);
    }
    const double p = prior_weight * (scale - 1.0);
    if (outside_unwidened(pose)) {
      const auto [radius, half_width] = step_border();
      cost += BoundsResiduals(bounds, pose, radius, half_width).squaredNorm();
    }
    return cost + p * p;
  };

  double lambda = 1e-3;
  double cost = cost_at(result.pose, result.focal_scale);
  Eigen::Matrix4d jtj;
  Eigen::Vector4d jtr;
  double chi2 = 0.0;
  for (int it = 0; it < options.max_iterations; ++it) {
    result.iterations = it + 1;
    border_ready = false;
    if (!outside_unwidened(result.pose)) {
      // Inside: the cost at the iterate has no bounds term whatever the border.
      normal_equations(result.pose, result.focal_scale, true, &jtj, &jtr, &chi2);
    } else {
      // The robust normal equations, the plain information (the step's border) and the cost at
      // the iterate under that border, in one pass.
      Eigen::Matrix4d plain_jtj;
      Eigen::Vector4d plain_jtr;
      double huber_cost = 0.0;
      normal_equations(result.pose, result.focal_scale, true, &jtj, &jtr, &chi2, &plain_jtj,
                       &plain_jtr, &huber_cost);
      border = border_of(plain_jtj);
      border_ready = true;
      Eigen::Matrix<double, 2, 3> jb;
      const Eigen::Vector2d rb =
          BoundsResiduals(bounds, result.pose, border.first, border.second, &jb);
      jtj.topLeftCorner<3, 3>() += jb.transpose() * jb;
      jtr.head<3>() += jb.transpose() * rb;
      const double p = prior_weight * (result.focal_scale - 1.0);
      cost = huber_cost + rb.squaredNorm() + p * p;
    }
    bool improved = false;
    Eigen::Vector4d step = Eigen::Vector4d::Zero();
    for (int attempt = 0; attempt < 8 && !improved; ++attempt) {
      // The damped step, solved at fixed size (no allocation).
      auto damped_step = [&](auto damped, const auto& gradient) {
        damped.diagonal() *= 1.0 + lambda;
        damped.diagonal().array() += 1e-12;
        return (-damped.ldlt().solve(gradient)).eval();
      };
      if (with_scale) {
        step = damped_step(Eigen::Matrix4d(jtj), jtr);
      } else {
        step.head<3>() = damped_step(Eigen::Matrix3d(jtj.topLeftCorner<3, 3>()), jtr.head<3>());
      }
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
  // The plain normal equations at the end (and, where the bounds may hold the pose, the robust
  // ones for the held test) in one pass.
  const bool outside = outside_unwidened(result.pose);
  Eigen::Matrix4d robust_jtj;
  Eigen::Vector4d robust_jtr;
  const double squares =
      normal_equations(result.pose, result.focal_scale, false, &jtj, &jtr, &result.chi2,
                       outside ? &robust_jtj : nullptr, outside ? &robust_jtr : nullptr);
  result.rms_px = std::sqrt(squares / (2.0 * n));
  // Pose uncertainty: the inverse of the information (the scale, when estimated, included).
  UncertaintyOf(jtj, dof, &result.covariance, &result.position_sigma_m, &result.heading_sigma_rad);
  result.bounded_covariance = result.covariance;
  if (outside) {
    // Where the pose is held at the border, the cost minimised has the bounds' information too.
    const double radius = bounds.radius_m + Widening(bounds, result.position_sigma_m);
    const double half_width = bounds.half_width_rad + Widening(bounds, result.heading_sigma_rad);
    Eigen::Matrix<double, 2, 3> jb;
    const Eigen::Vector2d rb = BoundsResiduals(bounds, result.pose, radius, half_width, &jb);
    result.bounds_excess_m = rb[0] * bounds.softness_m;
    result.bounds_excess_rad = rb[1] * bounds.softness_rad;
    // Held: outside by a hair, or stopped inside where the image's (robust) Gauss-Newton step
    // leads out of the bounds (LM stops at the wall when the border grows with the sigmas).
    Eigen::Vector4d step = Eigen::Vector4d::Zero();
    step.head(dof) = -robust_jtj.topLeftCorner(dof, dof).ldlt().solve(robust_jtr.head(dof));
    const Pose3Dof target{result.pose.x + step[1], result.pose.y + step[2],
                          result.pose.heading + step[0]};
    result.held_by_bounds = rb.squaredNorm() > 0.0 || !step.allFinite() ||
                            BoundsResiduals(bounds, target, radius, half_width).squaredNorm() > 0.0;
    if (rb.squaredNorm() > 0.0) {
      jtj.topLeftCorner<3, 3>() += jb.transpose() * jb;
      // The disk's curvature: rb_0 times the Hessian of (d - R) / softness, (I - n n') / (d
      // softness) across the radius (the multiplier times the border's curvature; not small
      // where the image pulls hard). The heading residual is linear.
      if (rb[0] > 0.0) {
        const Eigen::Vector2d offset(result.pose.x - bounds.centre.x(),
                                     result.pose.y - bounds.centre.y());
        const double distance = offset.norm();
        const Eigen::Vector2d n = offset / distance;
        jtj.block<2, 2>(1, 1) += rb[0] / (distance * bounds.softness_m) *
                                 (Eigen::Matrix2d::Identity() - n * n.transpose());
      }
      double position_sigma = 0.0, heading_sigma = 0.0;
      UncertaintyOf(jtj, dof, &result.bounded_covariance, &position_sigma, &heading_sigma);
    }
  }
  return result;
}

}  // namespace linetrack
