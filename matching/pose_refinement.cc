#include "matching/pose_refinement.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <utility>

#include "matching/constraints.h"
#include "matching/pose_refinement_steps.h"

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
    return EndpointResiduals(match, camera, ViewOf(pose, height, tilt), 1.0, nullptr);
  Eigen::Matrix<double, 2, 4> j4;
  const Eigen::Vector2d r = EndpointResiduals(match, camera, ViewOf(pose, height, tilt), 1.0, &j4);
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
                                  double height, double tilt, const PoseAndScale& pose,
                                  Eigen::Matrix<double, 2, 4>* jacobian) {
  return EndpointResiduals(match, camera, ViewOf(pose.pose, height, tilt), pose.focal_scale,
                           jacobian);
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
  return RefinePose(matches, camera, height, tilt, PoseAndScale{start, 1.0}, options);
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

RefinementProblem MakeRefinementProblem(const std::vector<LineMatch>& matches,
                                        const CameraIntrinsics& camera, double height, double tilt,
                                        const PoseRefinementOptions& options) {
  RefinementProblem problem{&matches, &camera, height, tilt, &options};
  // With enough lines the focal scale s absorbs a calibration error: MAP with the prior
  // s ~ N(1, focal_prior_sigma).
  problem.with_scale = options.focal_prior_sigma > 0.0 &&
                       static_cast<int>(matches.size()) >= options.min_matches_for_scale;
  problem.dof = problem.with_scale ? 4 : 3;
  problem.prior_weight = problem.with_scale ? 1.0 / options.focal_prior_sigma : 0.0;
  return problem;
}

double HuberCost(double r, double huber_px) {
  const double a = std::abs(r);
  return huber_px > 0.0 && a > huber_px ? huber_px * (2.0 * a - huber_px) : a * a;
}

namespace {

// The Huber weight of a whitened residual: 1 within the threshold, huber_px / |r| beyond.
double HuberWeight(double r, double huber_px) {
  const double a = std::abs(r);
  return huber_px > 0.0 && a > huber_px ? huber_px / a : 1.0;
}

// Adds the scale prior's terms, (prior_weight (s - 1))^2 in the cost, to normal equations.
void AddScalePrior(const RefinementProblem& problem, double scale, NormalEquations* system) {
  const double w2 = problem.prior_weight * problem.prior_weight;
  system->jtj(3, 3) += w2;
  system->jtr(3) += w2 * (scale - 1.0);
}

}  // namespace

Linearization Linearize(const RefinementProblem& problem, const Pose3Dof& pose, double scale,
                        Weighting weighting) {
  const bool robust = weighting != Weighting::kPlain;
  const bool plain = weighting != Weighting::kRobust;
  const bool both = robust && plain;
  const double huber_px = problem.options->huber_px;
  Linearization out;
  const PoseView view = ViewOf(pose, problem.height, problem.tilt);
  for (const LineMatch& m : *problem.matches) {
    Eigen::Matrix<double, 2, 4> j;
    const Eigen::Vector2d raw = EndpointResiduals(m, *problem.camera, view, scale, &j);
    out.squares_px2 += raw.squaredNorm();
    const Eigen::Vector2d r = m.whitening * raw;
    out.chi2 += r.squaredNorm();
    if (both) out.huber_cost += HuberCost(r[0], huber_px) + HuberCost(r[1], huber_px);
    j = m.whitening * j;
    if (!problem.with_scale) j.col(3).setZero();
    for (int k = 0; k < 2; ++k) {
      if (robust) {
        const double w = HuberWeight(r[k], huber_px);
        out.robust.jtj += w * j.row(k).transpose() * j.row(k);
        out.robust.jtr += w * j.row(k).transpose() * r[k];
      }
      if (plain) {
        out.plain.jtj += j.row(k).transpose() * j.row(k);
        out.plain.jtr += j.row(k).transpose() * r[k];
      }
    }
  }
  if (problem.with_scale) {
    if (robust) AddScalePrior(problem, scale, &out.robust);
    if (plain) AddScalePrior(problem, scale, &out.plain);
  }
  return out;
}

bool OutsideUnwidened(const PoseBounds& bounds, const Pose3Dof& pose) {
  return bounds.active &&
         (std::hypot(pose.x - bounds.centre.x(), pose.y - bounds.centre.y()) > bounds.radius_m ||
          std::abs(WrapAngle(pose.heading - bounds.heading)) > bounds.half_width_rad);
}

BoundsBorder BorderOf(const RefinementProblem& problem, const Eigen::Matrix4d& information) {
  const PoseBounds& bounds = problem.options->bounds;
  const auto [position_sigma, heading_sigma] = SigmasOf(information, problem.dof);
  return {bounds.radius_m + Widening(bounds, position_sigma),
          bounds.half_width_rad + Widening(bounds, heading_sigma)};
}

const BoundsBorder& StepBorder(const RefinementProblem& problem, RefinementState* state) {
  if (!state->border_ready) {
    const Linearization plain = Linearize(problem, state->pose, state->scale, Weighting::kPlain);
    state->border = BorderOf(problem, plain.plain.jtj);
    state->border_ready = true;
  }
  return state->border;
}

double TrialCost(const RefinementProblem& problem, const Pose3Dof& pose, double scale,
                 const BoundsBorder* border) {
  double cost = 0.0;
  const double huber_px = problem.options->huber_px;
  const PoseView view = ViewOf(pose, problem.height, problem.tilt);
  for (const LineMatch& m : *problem.matches) {
    const Eigen::Vector2d r =
        m.whitening * EndpointResiduals(m, *problem.camera, view, scale, nullptr);
    cost += HuberCost(r[0], huber_px) + HuberCost(r[1], huber_px);
  }
  const double p = problem.prior_weight * (scale - 1.0);
  if (border != nullptr) {
    cost += BoundsResiduals(problem.options->bounds, pose, border->radius_m, border->half_width_rad)
                .squaredNorm();
  }
  return cost + p * p;
}

RefinementState IterationZero(const RefinementProblem& problem, const Pose3Dof& start,
                              double start_scale) {
  RefinementState state;
  state.pose = start;
  state.scale = start_scale;
  const BoundsBorder* border =
      OutsideUnwidened(problem.options->bounds, start) ? &StepBorder(problem, &state) : nullptr;
  state.cost = TrialCost(problem, start, start_scale, border);
  return state;
}

NormalEquations IterateNormalEquations(const RefinementProblem& problem, RefinementState* state) {
  state->border_ready = false;
  const PoseBounds& bounds = problem.options->bounds;
  // Inside: the cost at the iterate has no bounds term whatever the border.
  if (!OutsideUnwidened(bounds, state->pose))
    return Linearize(problem, state->pose, state->scale, Weighting::kRobust).robust;
  // The robust normal equations, the plain information (the step's border) and the Huber cost
  // at the iterate, in one pass; then the bounds' residuals at that border.
  Linearization both = Linearize(problem, state->pose, state->scale, Weighting::kRobustAndPlain);
  state->border = BorderOf(problem, both.plain.jtj);
  state->border_ready = true;
  Eigen::Matrix<double, 2, 3> jb;
  const Eigen::Vector2d rb = BoundsResiduals(bounds, state->pose, state->border.radius_m,
                                             state->border.half_width_rad, &jb);
  both.robust.jtj.topLeftCorner<3, 3>() += jb.transpose() * jb;
  both.robust.jtr.head<3>() += jb.transpose() * rb;
  const double p = problem.prior_weight * (state->scale - 1.0);
  state->cost = both.huber_cost + rb.squaredNorm() + p * p;
  return both.robust;
}

namespace {

// (A + lambda diag(A) + 1e-12 I)^-1 (-b) at fixed size (no allocation).
template <typename Matrix, typename Gradient>
auto SolveDamped(Matrix damped, const Gradient& gradient, double lambda) {
  damped.diagonal() *= 1.0 + lambda;
  damped.diagonal().array() += 1e-12;
  return (-damped.ldlt().solve(gradient)).eval();
}

}  // namespace

Eigen::Vector4d DampedStep(const NormalEquations& system, double lambda, int dof) {
  Eigen::Vector4d step = Eigen::Vector4d::Zero();
  if (dof == 4) {
    step = SolveDamped(Eigen::Matrix4d(system.jtj), system.jtr, lambda);
  } else {
    step.head<3>() = SolveDamped(Eigen::Matrix3d(system.jtj.topLeftCorner<3, 3>()),
                                 system.jtr.head<3>(), lambda);
  }
  return step;
}

bool IsStepSuccessful(double trial_cost, double cost, double trial_scale) {
  return std::isfinite(trial_cost) && trial_cost <= cost && trial_scale > 0.5;
}

double DampingAfterSuccess(double lambda) {
  return std::max(lambda * 0.3, 1e-9);
}

double DampingAfterFailure(double lambda) {
  return lambda * 10.0;
}

StepOutcome TakeStep(const RefinementProblem& problem, const NormalEquations& system,
                     RefinementState* state) {
  StepOutcome out;
  for (int attempt = 0; attempt < 8 && !out.accepted; ++attempt) {
    out.step = DampedStep(system, state->lambda, problem.dof);
    const Pose3Dof trial{state->pose.x + out.step[1], state->pose.y + out.step[2],
                         state->pose.heading + out.step[0]};
    const double trial_scale = state->scale + out.step[3];
    const BoundsBorder* border =
        OutsideUnwidened(problem.options->bounds, trial) ? &StepBorder(problem, state) : nullptr;
    const double trial_cost = TrialCost(problem, trial, trial_scale, border);
    if (IsStepSuccessful(trial_cost, state->cost, trial_scale)) {
      state->pose = trial;
      state->scale = trial_scale;
      state->cost = trial_cost;
      state->lambda = DampingAfterSuccess(state->lambda);
      out.accepted = true;
    } else {
      state->lambda = DampingAfterFailure(state->lambda);
    }
  }
  return out;
}

namespace {

// Where the final pose lies outside the unwidened bounds: the border widened by the final
// sigmas, how far the pose exceeds it, whether the bounds hold the pose, and the covariance of the
// cost minimised (the image information plus the bounds' residuals', Gauss-Newton).
void BoundsAtTheEnd(const RefinementProblem& problem, const NormalEquations& robust,
                    Eigen::Matrix4d information, PoseRefinementResult* result) {
  const PoseBounds& bounds = problem.options->bounds;
  const int dof = problem.dof;
  const double radius = bounds.radius_m + Widening(bounds, result->position_sigma_m);
  const double half_width = bounds.half_width_rad + Widening(bounds, result->heading_sigma_rad);
  Eigen::Matrix<double, 2, 3> jb;
  const Eigen::Vector2d rb = BoundsResiduals(bounds, result->pose, radius, half_width, &jb);
  result->bounds_excess_m = rb[0] * bounds.softness_m;
  result->bounds_excess_rad = rb[1] * bounds.softness_rad;
  // Held: outside by a hair, or stopped inside where the image's (robust) Gauss-Newton step
  // leads out of the bounds (LM stops at the wall when the border grows with the sigmas).
  Eigen::Vector4d step = Eigen::Vector4d::Zero();
  step.head(dof) = -robust.jtj.topLeftCorner(dof, dof).ldlt().solve(robust.jtr.head(dof));
  const Pose3Dof target{result->pose.x + step[1], result->pose.y + step[2],
                        result->pose.heading + step[0]};
  result->held_by_bounds = rb.squaredNorm() > 0.0 || !step.allFinite() ||
                           BoundsResiduals(bounds, target, radius, half_width).squaredNorm() > 0.0;
  if (!(rb.squaredNorm() > 0.0)) return;
  information.topLeftCorner<3, 3>() += jb.transpose() * jb;
  // The disk's curvature: rb_0 times the Hessian of (d - R) / softness, (I - n n') / (d
  // softness) across the radius (the multiplier times the border's curvature; not small where
  // the image pulls hard). The heading residual is linear.
  if (rb[0] > 0.0) {
    const Eigen::Vector2d offset(result->pose.x - bounds.centre.x(),
                                 result->pose.y - bounds.centre.y());
    const double distance = offset.norm();
    const Eigen::Vector2d n = offset / distance;
    information.block<2, 2>(1, 1) +=
        rb[0] / (distance * bounds.softness_m) * (Eigen::Matrix2d::Identity() - n * n.transpose());
  }
  double position_sigma = 0.0, heading_sigma = 0.0;
  UncertaintyOf(information, dof, &result->bounded_covariance, &position_sigma, &heading_sigma);
}

// The result at the final iterate: the residuals' summary and the covariance of the plain normal
// equations (and, where the bounds may hold the pose, the robust ones for the held test, in the
// same pass).
void Summarize(const RefinementProblem& problem, PoseRefinementResult* result) {
  const bool outside = OutsideUnwidened(problem.options->bounds, result->pose);
  const Linearization end = Linearize(problem, result->pose, result->focal_scale,
                                      outside ? Weighting::kRobustAndPlain : Weighting::kPlain);
  result->chi2 = end.chi2;
  result->rms_px = std::sqrt(end.squares_px2 / (2.0 * problem.matches->size()));
  // Pose uncertainty: the inverse of the information (the scale, when estimated, included).
  UncertaintyOf(end.plain.jtj, problem.dof, &result->covariance, &result->position_sigma_m,
                &result->heading_sigma_rad);
  result->bounded_covariance = result->covariance;
  if (outside) BoundsAtTheEnd(problem, end.robust, end.plain.jtj, result);
}

}  // namespace

PoseRefinementResult RefinePose(const std::vector<LineMatch>& matches,
                                const CameraIntrinsics& camera, double height, double tilt,
                                const PoseAndScale& start, const PoseRefinementOptions& options) {
  PoseRefinementResult result;
  result.pose = start.pose;
  result.focal_scale = start.focal_scale;
  if (matches.empty()) return result;
  const RefinementProblem problem = MakeRefinementProblem(matches, camera, height, tilt, options);
  RefinementState state = IterationZero(problem, start.pose, start.focal_scale);
  for (int it = 0; it < options.max_iterations; ++it) {
    result.iterations = it + 1;
    const StepOutcome step = TakeStep(problem, IterateNormalEquations(problem, &state), &state);
    const bool small = step.step.norm() < options.step_tolerance;
    if (!step.accepted || small) {
      result.converged = step.accepted || small;
      break;
    }
  }
  result.pose = state.pose;
  result.focal_scale = state.scale;
  result.pose.heading = WrapAngle(result.pose.heading);
  Summarize(problem, &result);
  return result;
}

}  // namespace linetrack
