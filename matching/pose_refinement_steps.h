// The steps of RefinePose's Levenberg-Marquardt minimiser (pose_refinement.cc), named as in Ceres'
// trust-region minimiser: the residuals and their normal equations at a point (Linearize), the
// bounds' border and terms, the cost of a trial point (TrialCost), the damped step (DampedStep)
// and the acceptance of a step (IsStepSuccessful, with the damping's update). RefinePose is the
// interface; these are declared for the tests that check each step on its own.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "matching/pose_refinement.h"

namespace linetrack {

// What RefinePose minimises: the matches' whitened endpoint residuals (Huber-weighted), seen by
// `camera` at `height` and `tilt`, the focal-scale prior s ~ N(1, 1 / prior_weight) and the
// residuals of options->bounds. Parameters (heading, x, y) and, when with_scale, the scale s.
struct RefinementProblem {
  const std::vector<LineMatch>* matches = nullptr;
  const CameraIntrinsics* camera = nullptr;
  double height = 0.0;  // metres
  double tilt = 0.0;    // radians, positive down
  const PoseRefinementOptions* options = nullptr;
  bool with_scale = false;    // the focal scale is estimated (options and enough matches)
  int dof = 3;                // 4 with the scale
  double prior_weight = 0.0;  // 1 / focal_prior_sigma with the scale, else 0
};
RefinementProblem MakeRefinementProblem(const std::vector<LineMatch>& matches,
                                        const CameraIntrinsics& camera, double height, double tilt,
                                        const PoseRefinementOptions& options);

// Gauss-Newton normal equations J' W J delta = -J' W r over (heading, x, y, scale): jtj is
// J' W J (the information when W = I) and jtr is J' W r.
struct NormalEquations {
  Eigen::Matrix4d jtj = Eigen::Matrix4d::Zero();
  Eigen::Vector4d jtr = Eigen::Vector4d::Zero();
};

// The weightings a pass over the matches accumulates normal equations for: the Huber weights
// (the minimised cost's Gauss-Newton approximation), unit weights (the information, for the
// covariance and the bounds' border), or both.
enum class Weighting { kRobust, kPlain, kRobustAndPlain };

// The residuals at one point and their normal equations, the scale prior's terms included.
struct Linearization {
  NormalEquations robust;    // Huber weights w = min(1, huber_px / |r|) (kRobust, kRobustAndPlain)
  NormalEquations plain;     // unit weights (kPlain, kRobustAndPlain)
  double squares_px2 = 0.0;  // sum of the squared pixel residuals (not whitened)
  double chi2 = 0.0;         // sum of the squared whitened residuals
  double huber_cost = 0.0;   // sum of the Huber costs of the whitened residuals (kRobustAndPlain)
};
Linearization Linearize(const RefinementProblem& problem, const Pose3Dof& pose, double scale,
                        Weighting weighting);

// The Huber cost of a whitened residual r for threshold k: r^2 when |r| <= k (or k = 0), else
// k (2 |r| - k).
double HuberCost(double r, double huber_px);

// The bounds' border for a step (PoseBounds): radius_m and half_width_rad widened by `sigmas`
// times the position and heading standard deviations of the information `information` (the
// plain normal equations at the step's iterate); infinite where it gives no finite, non-negative
// variances.
struct BoundsBorder {
  double radius_m = 0.0;
  double half_width_rad = 0.0;
};
BoundsBorder BorderOf(const RefinementProblem& problem, const Eigen::Matrix4d& information);

// True when the bounds are active and `pose` lies outside their unwidened region (the disk of
// radius_m, the interval of half_width_rad): only there can the bounds' residuals be non-zero.
bool OutsideUnwidened(const PoseBounds& bounds, const Pose3Dof& pose);

// The iterate of the minimiser and its damping. `border` is the current step's bounds' border,
// computed from the iterate when first needed (most refinements stay inside the bounds) and held
// during the step's trials, as the bounds' Jacobian holds it.
struct RefinementState {
  Pose3Dof pose;
  double scale = 1.0;
  double cost = 0.0;     // TrialCost of the iterate
  double lambda = 1e-3;  // Levenberg-Marquardt damping
  bool border_ready = false;
  BoundsBorder border;
};

// The step's border, computed from the plain information at the iterate when not yet known.
const BoundsBorder& StepBorder(const RefinementProblem& problem, RefinementState* state);

// The cost at a trial point: the Huber costs of the whitened residuals, plus the squared bounds'
// residuals at `border` (null: the pose is inside the unwidened bounds, no bounds term), plus the
// squared scale-prior residual (prior_weight (s - 1))^2.
double TrialCost(const RefinementProblem& problem, const Pose3Dof& pose, double scale,
                 const BoundsBorder* border);

// Ceres' IterationZero: the state at the start point, its cost under the start's border.
RefinementState IterationZero(const RefinementProblem& problem, const Pose3Dof& start,
                              double start_scale);

// The normal equations of a step at the iterate: Huber-weighted; where the iterate lies outside
// the unwidened bounds, with the bounds' residuals at the step's border (computed here from the
// same pass) added, and the iterate's cost re-evaluated under that border. Clears the previous
// step's border.
NormalEquations IterateNormalEquations(const RefinementProblem& problem, RefinementState* state);

// The Levenberg-Marquardt step (Marquardt's scaling): (A + lambda diag(A) + 1e-12 I) delta =
// -b for the normal equations (A, b), solved at the problem's size (the scale component 0
// without it). Order (heading, x, y, scale).
Eigen::Vector4d DampedStep(const NormalEquations& system, double lambda, int dof);

// The acceptance of a trial point: its cost finite and not above the iterate's, its focal scale
// above 0.5.
bool IsStepSuccessful(double trial_cost, double cost, double trial_scale);

// The damping after an accepted step (times 0.3, at least 1e-9) and after a rejected one
// (times 10).
double DampingAfterSuccess(double lambda);
double DampingAfterFailure(double lambda);

// One iteration's trials: up to 8 damped steps from the iterate, the damping raised after each
// rejected one; the first accepted moves the iterate and lowers the damping.
struct StepOutcome {
  Eigen::Vector4d step = Eigen::Vector4d::Zero();  // the last step tried
  bool accepted = false;
};
StepOutcome TakeStep(const RefinementProblem& problem, const NormalEquations& system,
                     RefinementState* state);

}  // namespace linetrack
