// The steps of RefinePose's Levenberg-Marquardt minimiser, each on its own: the normal equations
// against those of a finite-difference Jacobian (Huber weights, whitening, focal scale and its
// prior), a Gauss-Newton step on an exact scene, the acceptance rule and the damping, and the
// bounds' border and terms.
#include "matching/pose_refinement_steps.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "scene_fixture.h"

namespace linetrack {
namespace {

constexpr double kJacobianTol = 1e-5;  // relative, analytic vs central differences
constexpr double kExactTol = 1e-12;    // relative, sums of the same terms

// An exact view of the hall, its matches and the refinement problem over them (kept together:
// the problem points at the matches and the options).
class ExactRefinement {
 public:
  ExactRefinement(const testing::HallFixture& hall, std::mt19937_64& rng,
                  const PoseRefinementOptions& refinement_options = {})
      : view(hall.RandomView(rng, 6)),
        truth(view.pose.Planar()),
        matches(testing::ExactLineMatches(hall, view)),
        options(refinement_options),
        problem(MakeRefinementProblem(matches, hall.camera(), view.pose.height, view.pose.tilt,
                                      options)) {}
  ExactRefinement(const ExactRefinement&) = delete;
  ExactRefinement& operator=(const ExactRefinement&) = delete;

  const testing::ExactView view;
  const Pose3Dof truth;
  const std::vector<LineMatch> matches;
  const PoseRefinementOptions options;
  const RefinementProblem problem;
};

// Exact matches with endpoints moved by N(0, 2 px) and a whitening of its own per match (an
// upper-triangular W with positive diagonal), so that residuals, weights and W all matter.
std::vector<LineMatch> NoisyWhitenedMatches(const testing::HallFixture& hall,
                                            const testing::ExactView& view, std::mt19937_64& rng) {
  std::normal_distribution<double> pixel(0.0, 2.0);
  std::uniform_real_distribution<double> unit(0.5, 1.5);
  std::vector<LineMatch> matches = testing::ExactLineMatches(hall, view);
  for (LineMatch& m : matches) {
    m.observed.a += Eigen::Vector2d(pixel(rng), pixel(rng));
    m.observed.b += Eigen::Vector2d(pixel(rng), pixel(rng));
    m.whitening << unit(rng), unit(rng) - 1.0, 0.0, unit(rng);
  }
  return matches;
}

// The whitened residuals of all matches at (pose, scale), stacked.
Eigen::VectorXd Whitened(const std::vector<LineMatch>& matches, const CameraIntrinsics& camera,
                         const RobotPose& mount, const PoseAndScale& at) {
  Eigen::VectorXd r(2 * matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    r.segment<2>(2 * i) = matches[i].whitening * EndpointResiduals(matches[i], camera, mount.height,
                                                                   mount.tilt, at, nullptr);
  }
  return r;
}

// `at` with parameter k (0 heading, 1 x, 2 y, 3 scale) moved by `step`.
PoseAndScale Moved(PoseAndScale at, int k, double step) {
  (k == 0 ? at.pose.heading : k == 1 ? at.pose.x : k == 2 ? at.pose.y : at.focal_scale) += step;
  return at;
}

void ExpectNear(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& expected, double tol) {
  ASSERT_EQ(analytic.rows(), expected.rows());
  ASSERT_EQ(analytic.cols(), expected.cols());
  for (Eigen::Index i = 0; i < analytic.rows(); ++i) {
    for (Eigen::Index j = 0; j < analytic.cols(); ++j) {
      EXPECT_NEAR(analytic(i, j), expected(i, j), tol * std::max(1.0, std::abs(expected(i, j))))
          << "(" << i << ", " << j << ")";
    }
  }
}

// The plain normal equations are J'J and J'r of the whitened residuals with J from central
// differences, plus the scale prior's (w^2 at (3, 3), w^2 (s - 1) in the gradient); the robust
// ones weight each residual by min(1, k / |r|); chi2 and the Huber cost are the residuals' sums.
TEST(RefinementSteps, NormalEquationsAreThoseOfTheFiniteDifferenceJacobian) {
  testing::HallFixture hall;
  std::mt19937_64 rng(21);
  for (int v = 0; v < 10; ++v) {
    const testing::ExactView view = hall.RandomView(rng, 6);
    const std::vector<LineMatch> matches = NoisyWhitenedMatches(hall, view, rng);
    PoseRefinementOptions options;
    options.focal_prior_sigma = 0.02;
    options.huber_px = 1.5;  // below the noise: some residuals are down-weighted
    const RefinementProblem problem =
        MakeRefinementProblem(matches, hall.camera(), view.pose.height, view.pose.tilt, options);
    ASSERT_TRUE(problem.with_scale);
    const PoseAndScale at{{view.pose.x + 0.05, view.pose.y - 0.03, view.pose.heading + 0.01}, 1.01};
    const Eigen::VectorXd r = Whitened(matches, hall.camera(), view.pose, at);
    Eigen::MatrixXd j(r.size(), 4);
    for (int k = 0; k < 4; ++k) {
      const double step = 1e-6;
      j.col(k) = (Whitened(matches, hall.camera(), view.pose, Moved(at, k, step)) -
                  Whitened(matches, hall.camera(), view.pose, Moved(at, k, -step))) /
                 (2.0 * step);
    }
    Eigen::VectorXd w(r.size());
    double huber_cost = 0.0;
    for (Eigen::Index i = 0; i < r.size(); ++i) {
      w[i] = std::min(1.0, options.huber_px / std::abs(r[i]));
      huber_cost += HuberCost(r[i], options.huber_px);
    }
    const double w2 = problem.prior_weight * problem.prior_weight;
    Eigen::Matrix4d prior = Eigen::Matrix4d::Zero();
    prior(3, 3) = w2;
    Eigen::Vector4d prior_gradient = Eigen::Vector4d::Zero();
    prior_gradient(3) = w2 * (at.focal_scale - 1.0);

    const Linearization l = Linearize(problem, at.pose, at.focal_scale, Weighting::kRobustAndPlain);
    ExpectNear(l.plain.jtj, j.transpose() * j + prior, kJacobianTol);
    ExpectNear(l.plain.jtr, j.transpose() * r + prior_gradient, kJacobianTol);
    ExpectNear(l.robust.jtj, j.transpose() * w.asDiagonal() * j + prior, kJacobianTol);
    ExpectNear(l.robust.jtr, j.transpose() * w.asDiagonal() * r + prior_gradient, kJacobianTol);
    EXPECT_NEAR(l.chi2, r.squaredNorm(), kExactTol * r.squaredNorm());
    EXPECT_NEAR(l.huber_cost, huber_cost, kExactTol * huber_cost);
    EXPECT_LT(w.minCoeff(), 1.0);  // the test exercises the Huber weights
    // One weighting alone gives the same sums as both together.
    const Linearization robust = Linearize(problem, at.pose, at.focal_scale, Weighting::kRobust);
    const Linearization plain = Linearize(problem, at.pose, at.focal_scale, Weighting::kPlain);
    EXPECT_TRUE(robust.robust.jtj == l.robust.jtj && robust.robust.jtr == l.robust.jtr);
    EXPECT_TRUE(plain.plain.jtj == l.plain.jtj && plain.plain.jtr == l.plain.jtr);
    EXPECT_EQ(plain.chi2, l.chi2);
  }
}

// On exact data one Gauss-Newton step (no damping) from a pose 2 cm and 0.3 degree off lands
// within a twentieth of that error of the truth (the residuals are nearly linear there:
// quadratic convergence), and at the truth the step is zero.
TEST(RefinementSteps, GaussNewtonStepOnAnExactScene) {
  constexpr double kContraction = 0.05;
  constexpr double kZeroStep = 1e-9;
  testing::HallFixture hall;
  std::mt19937_64 rng(22);
  for (int v = 0; v < 10; ++v) {
    const ExactRefinement exact(hall, rng);
    const RefinementProblem& problem = exact.problem;
    const Pose3Dof& truth = exact.truth;
    const Pose3Dof start{truth.x + 0.02, truth.y - 0.01, truth.heading + DegToRad(0.3)};
    RefinementState state = IterationZero(problem, start, 1.0);
    const Eigen::Vector4d step = DampedStep(IterateNormalEquations(problem, &state), 0.0, 3);
    EXPECT_EQ(step[3], 0.0);  // no scale without the prior
    const Eigen::Vector3d before(start.heading - truth.heading, start.x - truth.x,
                                 start.y - truth.y);
    const Eigen::Vector3d after = before + step.head<3>();
    EXPECT_LT(after.norm(), kContraction * before.norm()) << "view " << v;

    RefinementState at_truth = IterationZero(problem, truth, 1.0);
    EXPECT_LT(at_truth.cost, 1e-12);
    EXPECT_LT(DampedStep(IterateNormalEquations(problem, &at_truth), 1e-3, 3).norm(), kZeroStep);
  }
}

// A trial is accepted when its cost is finite and not above the iterate's and its focal scale
// stays above 0.5; the damping falls by 0.3 (to 1e-9 at least) after an accepted step and rises
// tenfold after a rejected one.
TEST(RefinementSteps, AcceptanceRuleAndDamping) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(IsStepSuccessful(1.0, 1.0, 1.0));
  EXPECT_TRUE(IsStepSuccessful(0.5, 1.0, 0.51));
  EXPECT_FALSE(IsStepSuccessful(1.0 + 1e-12, 1.0, 1.0));
  EXPECT_FALSE(IsStepSuccessful(nan, 1.0, 1.0));
  EXPECT_FALSE(IsStepSuccessful(inf, inf, 1.0));
  EXPECT_FALSE(IsStepSuccessful(0.5, 1.0, 0.5));
  EXPECT_DOUBLE_EQ(DampingAfterSuccess(1e-3), 3e-4);
  EXPECT_EQ(DampingAfterSuccess(1e-9), 1e-9);
  EXPECT_DOUBLE_EQ(DampingAfterFailure(1e-3), 1e-2);

  // TakeStep on an exact scene: the accepted step lowers the cost and the damping, and moves
  // the iterate by that step.
  testing::HallFixture hall;
  std::mt19937_64 rng(23);
  const ExactRefinement exact(hall, rng);
  const RefinementProblem& problem = exact.problem;
  const Pose3Dof& truth = exact.truth;
  RefinementState state = IterationZero(problem, {truth.x + 0.1, truth.y, truth.heading}, 1.0);
  const RefinementState before = state;
  const StepOutcome outcome = TakeStep(problem, IterateNormalEquations(problem, &state), &state);
  ASSERT_TRUE(outcome.accepted);
  EXPECT_LT(state.cost, before.cost);
  EXPECT_LT(state.lambda, before.lambda);
  EXPECT_EQ(state.pose.x, before.pose.x + outcome.step[1]);
  EXPECT_EQ(state.pose.heading, before.pose.heading + outcome.step[0]);
}

// The border widens radius_m and half_width_rad by `sigmas` standard deviations of the
// information (infinitely when it gives no covariance); outside the unwidened bounds the step's
// normal equations gain the bounds' J'J and J'r and the iterate's cost their squared residuals.
TEST(RefinementSteps, BoundsBorderAndTerms) {
  testing::HallFixture hall;
  std::mt19937_64 rng(24);
  const testing::ExactView view = hall.RandomView(rng, 6);
  const std::vector<LineMatch> matches = testing::ExactLineMatches(hall, view);
  const Pose3Dof truth = view.pose.Planar();
  PoseRefinementOptions options;
  options.bounds.active = true;
  options.bounds.centre = {truth.x + 1.0, truth.y};
  options.bounds.radius_m = 0.4;
  options.bounds.heading = truth.heading;
  options.bounds.half_width_rad = DegToRad(4.0);
  options.bounds.sigmas = 3.0;
  const RefinementProblem problem =
      MakeRefinementProblem(matches, hall.camera(), view.pose.height, view.pose.tilt, options);

  const Linearization at_truth = Linearize(problem, truth, 1.0, Weighting::kPlain);
  const Eigen::Matrix3d c = at_truth.plain.jtj.topLeftCorner<3, 3>().inverse();
  const BoundsBorder border = BorderOf(problem, at_truth.plain.jtj);
  EXPECT_NEAR(border.radius_m, 0.4 + 3.0 * LargestPositionSigma(c.block<2, 2>(1, 1)), 1e-9);
  EXPECT_NEAR(border.half_width_rad, DegToRad(4.0) + 3.0 * std::sqrt(c(0, 0)), 1e-9);
  const BoundsBorder indefinite = BorderOf(problem, -Eigen::Matrix4d::Identity());
  EXPECT_TRUE(std::isinf(indefinite.radius_m) && std::isinf(indefinite.half_width_rad));

  ASSERT_TRUE(OutsideUnwidened(options.bounds, truth));
  EXPECT_FALSE(OutsideUnwidened(options.bounds, {truth.x + 1.0, truth.y, truth.heading}));
  RefinementState state = IterationZero(problem, truth, 1.0);
  const NormalEquations system = IterateNormalEquations(problem, &state);
  ASSERT_TRUE(state.border_ready);
  EXPECT_EQ(state.border.radius_m, border.radius_m);
  Eigen::Matrix<double, 2, 3> jb;
  const Eigen::Vector2d rb =
      BoundsResiduals(options.bounds, truth, border.radius_m, border.half_width_rad, &jb);
  ASSERT_GT(rb[0], 0.0);  // 1 m from the centre, beyond the widened radius
  const Linearization image = Linearize(problem, truth, 1.0, Weighting::kRobust);
  ExpectNear(system.jtj.topLeftCorner<3, 3>() - image.robust.jtj.topLeftCorner<3, 3>(),
             jb.transpose() * jb, kExactTol);
  ExpectNear(system.jtr.head<3>() - image.robust.jtr.head<3>(), jb.transpose() * rb, kExactTol);
  EXPECT_NEAR(state.cost, rb.squaredNorm(), kExactTol * rb.squaredNorm());  // exact: no image cost
  EXPECT_LT(TrialCost(problem, truth, 1.0, nullptr), 1e-12);  // exact data, no bounds term
  EXPECT_NEAR(TrialCost(problem, truth, 1.0, &border), rb.squaredNorm(),
              kExactTol * rb.squaredNorm());
}

}  // namespace
}  // namespace linetrack
