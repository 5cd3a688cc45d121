// The pose covariance of tracked poses (tracking/integrity/): the residual's Jacobians against
// finite differences, the Woodbury whitening against a dense inverse, the chi-square and NEES
// tools, and the covariance against seeded Monte Carlo runs of the solve on exact synthetic
// scenes whose errors follow the stated model.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <random>

#include "tests/tracking/integrity_scene.h"
#include "tracking/integrity/consistency.h"
#include "tracking/integrity/edge_pose_solver.h"
#include "tracking/integrity/integrity_monitor.h"
#include "tracking/integrity/ros_covariance.h"

namespace linetrack {
namespace {

using integrity_test::DrawCamera;
using integrity_test::DrawRobotCamera;
using integrity_test::Observe;
using integrity_test::RoomEdges;
using integrity_test::SceneNoise;
using integrity_test::SolverOptionsFor;
using integrity_test::TestCamera;
using integrity_test::TestRobotPose;

constexpr double kJacobianStep = 1e-6;
constexpr double kJacobianTol = 1e-4;  // relative to the row's largest entry
constexpr double kExactPositionTolM = 1e-7;
constexpr double kExactRotationTolRad = 1e-8;
constexpr int kMonteCarloRuns = 400;
// With the stated model alone (no edge-level scale estimated), the NEES mean within 12 % of the
// degrees of freedom (400 runs: the mean's own scatter is sqrt(2 dof / 400) / dof, 4 % at dof 3,
// 3 % at 6). The estimated scale lambda >= 1 only widens the covariance: its mean may fall to
// 75 % of the dof. The 99 % region holds at least 97.5 % either way.
constexpr double kMeanNeesTol = 0.12;
constexpr double kMinScaledMeanNees = 0.75;
constexpr double kMin99Share = 0.975;
constexpr double kMinEstimateGain = 0.2;  // share of the position sigma that estimation saves

Eigen::Isometry3d TestFreePose() {
  WorldTwist tilt = WorldTwist::Zero();
  tilt.tail<3>() << 0.03, -0.02, 0.01;
  return ApplyWorldTwist(CamFromWorld(TestRobotPose()), tilt);
}

double ResidualAt(const EdgeObservation& o, const Eigen::Isometry3d& pose,
                  const CameraIntrinsics& camera) {
  return LinearisePointOnEdge(o.a, o.b, pose, camera, o.points[0]).residual;
}

TEST(IntegrityResidual, IsTheSignedPointToLineDistanceOfTheRefinement) {
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Isometry3d pose = CamFromWorld(TestRobotPose());
  const Eigen::Vector3d a(6.0, -2.0, 0.0), b(6.0, 2.0, 0.5);
  const Eigen::Vector2d pa = camera.Project(pose * a), pb = camera.Project(pose * b);
  const Eigen::Vector2d d = (pb - pa).normalized();
  const Eigen::Vector2d normal(-d.y(), d.x());  // the refinement's sign
  const Eigen::Vector2d on_line = 0.3 * pa + 0.7 * pb;
  EXPECT_NEAR(LinearisePointOnEdge(a, b, pose, camera, on_line).residual, 0.0, 1e-9);
  EXPECT_NEAR(LinearisePointOnEdge(a, b, pose, camera, on_line + 1.7 * normal).residual, 1.7, 1e-9);
}

TEST(IntegrityResidual, JacobiansMatchFiniteDifferences) {
  const CameraIntrinsics camera = TestCamera();
  std::mt19937 random(7);
  const std::vector<EdgeObservation> observations =
      Observe(RoomEdges(), camera, TestFreePose(), SceneNoise{0.5}, &random);
  ASSERT_GE(observations.size(), 8u);
  for (const EdgeObservation& o : observations) {
    const EdgePointResidual r = LinearisePointOnEdge(o.a, o.b, TestFreePose(), camera, o.points[0]);
    const double scale = std::max(1.0, r.d_twist.cwiseAbs().maxCoeff());
    for (int j = 0; j < 6; ++j) {
      WorldTwist step = WorldTwist::Zero();
      step[j] = kJacobianStep;
      const double numeric = (ResidualAt(o, ApplyWorldTwist(TestFreePose(), step), camera) -
                              ResidualAt(o, ApplyWorldTwist(TestFreePose(), -step), camera)) /
                             (2.0 * kJacobianStep);
      EXPECT_NEAR(r.d_twist[j], numeric, kJacobianTol * scale) << "twist " << j;
    }
    CameraIntrinsics moved[3] = {camera, camera, camera};
    moved[0].px *= 1.0 + kJacobianStep;
    moved[0].py *= 1.0 + kJacobianStep;
    moved[1].u0 += kJacobianStep;
    moved[2].v0 += kJacobianStep;
    for (int j = 0; j < 3; ++j) {
      const double numeric = (ResidualAt(o, TestFreePose(), moved[j]) - r.residual) / kJacobianStep;
      EXPECT_NEAR(r.d_camera[j], numeric, 1e-3 * std::max(1.0, std::abs(numeric)))
          << "camera " << j;
    }
  }
}

TEST(IntegrityResidual, CasingOffsetsAreTheEndResidualsOfAShiftedEdge) {
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Isometry3d pose = TestFreePose();
  EdgeObservation jamb;  // a jamb on a wall x = 6 seen obliquely, pulled along the wall
  jamb.a = Eigen::Vector3d(6.0, 1.2, 0.0);
  jamb.b = Eigen::Vector3d(6.0, 1.2, 2.05);
  jamb.casing_direction = Eigen::Vector3d(0.0, 1.0, 0.0);
  const Eigen::Vector2d k = CasingOffsets(jamb, pose, camera);
  const Eigen::Vector2d pa = camera.Project(pose * jamb.a), pb = camera.Project(pose * jamb.b);
  constexpr double kShiftM = 1e-5;
  const Eigen::Vector3d shift = kShiftM * jamb.casing_direction;
  for (int end = 0; end < 2; ++end) {
    const Eigen::Vector2d& p = end == 0 ? pa : pb;
    const double numeric =
        LinearisePointOnEdge(jamb.a + shift, jamb.b + shift, pose, camera, p).residual / kShiftM;
    EXPECT_NEAR(k[end], numeric, 1e-4 * std::abs(numeric)) << "end " << end;
  }
  // A shift along the edge itself moves nothing.
  jamb.casing_direction = Eigen::Vector3d(0.0, 0.0, 1.0);
  EXPECT_NEAR(CasingOffsets(jamb, pose, camera).norm(), 0.0, 1e-9);
}

// The robot's unknowns and its height and tilt map to world twists as TwistOf... say.
TEST(IntegrityResidual, RobotParametersMapToWorldTwists) {
  for (double roll_deg : {0.0, 2.0}) {  // a camera held level, and one rolled on its mount
    RobotPose robot = TestRobotPose();
    robot.roll = DegToRad(roll_deg);
    const Eigen::Isometry3d pose = CamFromWorld(robot);
    const PoseParameterisation parameters(KnownHeightTilt{robot.height, robot.tilt, robot.roll});
    const Eigen::MatrixXd unknowns = parameters.TwistOfUnknowns();
    for (int j = 0; j < 3; ++j) {
      Eigen::VectorXd delta = Eigen::VectorXd::Zero(3);
      delta[j] = kJacobianStep;
      const Eigen::Isometry3d moved = parameters.Apply(pose, delta);
      const WorldTwist numeric = WorldTwistBetween(pose, moved) / kJacobianStep;
      EXPECT_LT((numeric - unknowns.col(j)).norm(), 1e-5) << "unknown " << j;
      EXPECT_NEAR(RollOf(moved), robot.roll, 1e-12);  // the known roll is kept
    }
    const Eigen::MatrixXd robot_map = parameters.TwistOfRobotParameters(pose);
    RobotPose higher = robot, tilted = robot, rolled = robot;
    higher.height += kJacobianStep;
    tilted.tilt += kJacobianStep;
    rolled.roll += kJacobianStep;
    int k = 0;
    for (const RobotPose& changed : {higher, tilted, rolled}) {
      const WorldTwist numeric = WorldTwistBetween(pose, CamFromWorld(changed)) / kJacobianStep;
      EXPECT_LT((numeric - robot_map.col(k)).norm(), 1e-5)
          << "parameter " << k << " roll " << roll_deg;
      ++k;
    }
  }
}

TEST(IntegrityResidual, WorldTwistRoundTrip) {
  WorldTwist twist;
  twist << 0.3, -0.2, 0.1, 0.2, -0.1, 0.4;
  const Eigen::Isometry3d pose = CamFromWorld(TestRobotPose());
  EXPECT_LT((WorldTwistBetween(pose, ApplyWorldTwist(pose, twist)) - twist).norm(), 1e-12);
}

// J' (D^-1 + U S U')^-1 J by the Woodbury kernel equals the dense inverse, also for a singular S
// (a latch shift alone).
TEST(IntegrityWhitening, WoodburyKernelMatchesTheDenseInverse) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> uniform(0.5, 2.0);
  const int m = 9;
  Eigen::MatrixXd basis(m, 2), jacobian(m, 3);
  Eigen::VectorXd weights(m);
  for (int i = 0; i < m; ++i) {
    const double t = i / (m - 1.0);
    basis.row(i) << 1.0 - t, t;
    weights[i] = uniform(random);
    for (int j = 0; j < 3; ++j)
      jacobian(i, j) = uniform(random) - 1.25;
  }
  for (double model : {0.0, 0.7}) {
    Eigen::Matrix2d edge;
    edge << model * model + 0.09, 0.09, 0.09, 0.25 * model * model + 0.09;
    const Eigen::MatrixXd dense =
        (Eigen::MatrixXd(weights.cwiseInverse().asDiagonal()) + basis * edge * basis.transpose())
            .inverse();
    const Eigen::MatrixXd jd = jacobian.transpose() * weights.asDiagonal();
    const Eigen::Matrix2d kernel =
        WoodburyKernel(edge, basis.transpose() * weights.asDiagonal() * basis);
    const Eigen::MatrixXd woodbury =
        jd * jacobian - (jd * basis) * kernel * (jd * basis).transpose();
    EXPECT_LT((woodbury - jacobian.transpose() * dense * jacobian).norm(), 1e-10) << model;
  }
}

TEST(IntegrityConsistency, ChiSquareQuantilesOfTheTables) {
  EXPECT_NEAR(ChiSquareUpperQuantile(1, 0.01), 6.6349, 1e-4);
  EXPECT_NEAR(ChiSquareUpperQuantile(2, 0.01), -2.0 * std::log(0.01), 1e-9);
  EXPECT_NEAR(ChiSquareUpperQuantile(3, 0.001), 16.2662, 1e-4);
  EXPECT_NEAR(ChiSquareUpperQuantile(6, 0.01), 16.8119, 1e-4);
  EXPECT_NEAR(ChiSquareUpperQuantile(3, 0.5), 2.3660, 1e-4);
  EXPECT_NEAR(ChiSquareUpperTail(4, ChiSquareUpperQuantile(4, 1e-6)), 1e-6, 1e-15);
}

// NEES of exact Gaussian draws from a known covariance fill the chi-square regions as they say.
TEST(IntegrityConsistency, NeesOfExactGaussiansFillTheChiSquareRegions) {
  constexpr int kDraws = 20000;
  Eigen::Matrix3d covariance;
  covariance << 4.0, 1.0, 0.5, 1.0, 2.0, -0.3, 0.5, -0.3, 1.0;
  const Eigen::Matrix3d root = covariance.llt().matrixL();
  std::mt19937 random(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  CalibrationTally tally(3);
  for (int i = 0; i < kDraws; ++i) {
    const Eigen::Vector3d e =
        root * Eigen::Vector3d(normal(random), normal(random), normal(random));
    tally.Add(Nees(e, covariance), 1.0, e.norm());
  }
  const CalibrationSummary s = tally.Summary();
  EXPECT_EQ(s.count, kDraws);
  EXPECT_NEAR(s.mean_nees, 3.0, 0.06);
  for (size_t i = 0; i < s.kLevels.size(); ++i) {
    const double sd = std::sqrt(s.kLevels[i] * (1.0 - s.kLevels[i]) / kDraws);
    EXPECT_NEAR(s.shares[i], s.kLevels[i], 4.0 * sd + 1e-4) << s.kLevels[i];
  }
  EXPECT_NE(s.Table("gaussian", "m").find("| gaussian | 20000 |"), std::string::npos);
}

// Exact measurements give the true pose back, for a robot and for a free camera.
TEST(EdgePoseSolver, ExactMeasurementsGiveTheTruth) {
  const CameraIntrinsics camera = TestCamera();
  const RobotPose robot = TestRobotPose();
  std::mt19937 random(1);
  for (bool free : {false, true}) {
    const Eigen::Isometry3d truth = free ? TestFreePose() : CamFromWorld(robot);
    const PoseParameterisation parameters =
        free ? PoseParameterisation()
             : PoseParameterisation(KnownHeightTilt{robot.height, robot.tilt});
    const std::vector<EdgeObservation> observations =
        Observe(RoomEdges(), camera, truth, SceneNoise(), &random);
    WorldTwist offset;
    offset << 0.05, -0.04, free ? 0.03 : 0.0, 0.0, 0.0, 0.02;
    const EdgePoseSolution s = SolveEdgePose(observations, camera, ApplyWorldTwist(truth, offset),
                                             parameters, EdgePoseSolverOptions());
    ASSERT_TRUE(s.ok) << s.reason;
    const WorldTwist error = WorldTwistBetween(truth, s.cam_from_world);
    EXPECT_LT(error.head<3>().norm(), kExactPositionTolM) << free;
    EXPECT_LT(error.tail<3>().norm(), kExactRotationTolRad) << free;
  }
}

struct MonteCarloFigures {
  CalibrationSummary unknowns, world;
};

// Seeded Monte Carlo of the solve: each run draws the camera, the robot's height, tilt and roll
// and the edge points' errors from `noise`, solves from a start 2 cm / 0.3 degree off (the held
// parameters estimated or considered), and scores the estimate's NEES with its covariance (and
// for a robot, the 6 x 6 world twist's).
using Handling = ConsideredUncertainty::Handling;

MonteCarloFigures RunMonteCarlo(const SceneNoise& noise, bool free, int seed,
                                bool estimate_edge_scale, Handling handling) {
  const CameraIntrinsics nominal = TestCamera();
  const RobotPose robot = TestRobotPose();
  const PoseParameterisation parameters =
      free ? PoseParameterisation()
           : PoseParameterisation(KnownHeightTilt{robot.height, robot.tilt});
  EdgePoseSolverOptions options = SolverOptionsFor(noise);
  options.noise.estimate_edge_scale = estimate_edge_scale;
  options.considered.intrinsics = options.considered.mount = handling;
  std::mt19937 random(seed);
  CalibrationTally tally(parameters.dof()), world(6);
  for (int run = 0; run < kMonteCarloRuns; ++run) {
    const CameraIntrinsics camera = DrawCamera(nominal, noise, &random);
    const Eigen::Isometry3d truth = free ? TestFreePose() : DrawRobotCamera(robot, noise, &random);
    const std::vector<EdgeObservation> observations =
        Observe(RoomEdges(), camera, truth, noise, &random);
    WorldTwist offset;
    offset << 0.02, -0.01, 0.0, 0.0, 0.0, DegToRad(0.3);
    const EdgePoseSolution s =
        SolveEdgePose(observations, nominal, ApplyWorldTwist(truth, offset), parameters, options);
    EXPECT_TRUE(s.ok) << s.reason;
    if (!s.ok) continue;
    const Eigen::VectorXd error =
        free ? Eigen::VectorXd(WorldTwistBetween(truth, s.cam_from_world))
             : parameters.Difference(s.cam_from_world, CamFromWorld(robot));
    const Eigen::Vector2d sigmas = LargestSigmas(parameters, s.covariance);
    tally.Add(Nees(error, s.covariance), sigmas[0], error.head(free ? 3 : 2).norm());
    const WorldTwist world_error = WorldTwistBetween(truth, s.cam_from_world);
    world.Add(Nees(world_error, WorldTwistCovariance(s)), sigmas[0], world_error.head<3>().norm());
  }
  return {tally.Summary(), world.Summary()};
}

// Calibrated: NEES mean at the dof (within kMeanNeesTol), or between kMinScaledMeanNees and
// 1 + kMeanNeesTol of it when the edge-level scale is estimated; the 99 % region holding.
void ExpectCalibrated(const CalibrationSummary& s, bool scaled, const std::string& what) {
  const double ratio = s.mean_nees / s.dof;
  EXPECT_LE(ratio, 1.0 + kMeanNeesTol) << s.Table(what, "m");
  EXPECT_GE(ratio, scaled ? kMinScaledMeanNees : 1.0 - kMeanNeesTol) << s.Table(what, "m");
  EXPECT_GE(s.shares[2], kMin99Share) << s.Table(what, "m");
  std::cout << s.Table(what, "m");
}

SceneNoise EveryError() {
  SceneNoise noise;
  noise.point_px = 0.15;
  noise.model_m = 0.005;
  noise.latch_px = 0.3;
  noise.focal_relative = 0.005;
  noise.principal_point_px = 2.0;
  noise.height_m = 0.005;
  noise.tilt_rad = DegToRad(0.1);
  noise.roll_rad = DegToRad(0.1);
  return noise;
}

TEST(EdgePoseSolver, RobotCovarianceMatchesMonteCarloWithEveryError) {
  for (Handling handling : {Handling::kConsider, Handling::kEstimate}) {
    for (bool scaled : {false, true}) {
      const MonteCarloFigures figures = RunMonteCarlo(EveryError(), false, 21, scaled, handling);
      const std::string how = std::string(handling == Handling::kEstimate ? ", estimated" : "") +
                              (scaled ? ", lambda estimated" : ", stated model");
      ExpectCalibrated(figures.unknowns, scaled, "robot x, y, heading" + how);
      ExpectCalibrated(figures.world, scaled, "robot world twist" + how);
    }
  }
}

TEST(EdgePoseSolver, FreeCameraCovarianceMatchesMonteCarloWithEveryError) {
  for (Handling handling : {Handling::kConsider, Handling::kEstimate}) {
    for (bool scaled : {false, true}) {
      const std::string how = std::string(handling == Handling::kEstimate ? ", estimated" : "") +
                              (scaled ? ", lambda estimated" : ", stated model");
      ExpectCalibrated(RunMonteCarlo(EveryError(), true, 22, scaled, handling).unknowns, scaled,
                       "free camera" + how);
    }
  }
}

// Solving for the held parameters under their prior gives the marginal covariance
// (A - B (D + Sc^-1)^-1 B')^-1, never larger than the consider covariance A^-1 + A^-1 B Sc B' A^-1
// (D = J_c' S^-1 J_c >= B' A^-1 B); in the room, tilt and v0 are seen by the floor lines, so the
// position sigma shrinks by more than kMinEstimateGain.
TEST(EdgePoseSolver, EstimatingTheHeldParametersNeverWidensTheCovariance) {
  const RobotPose robot = TestRobotPose();
  const PoseParameterisation parameters(KnownHeightTilt{robot.height, robot.tilt});
  std::mt19937 random(31);
  EdgePoseSolverOptions options = SolverOptionsFor(EveryError());
  options.noise.estimate_edge_scale = false;
  const Eigen::Isometry3d truth = CamFromWorld(robot);
  const std::vector<EdgeObservation> observations =
      Observe(RoomEdges(), TestCamera(), truth, EveryError(), &random);
  options.considered.intrinsics = options.considered.mount = Handling::kConsider;
  const EdgePoseSolution held =
      SolveEdgePose(observations, TestCamera(), truth, parameters, options);
  options.considered.intrinsics = options.considered.mount = Handling::kEstimate;
  const EdgePoseSolution solved =
      SolveEdgePose(observations, TestCamera(), truth, parameters, options);
  ASSERT_TRUE(held.ok && solved.ok);
  EXPECT_EQ(solved.state_size(), 9);
  EXPECT_EQ(held.state_size(), 3);
  const Eigen::VectorXd gain =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(held.covariance - solved.covariance)
          .eigenvalues();
  EXPECT_GE(gain.minCoeff(), -1e-9 * held.covariance.norm());
  EXPECT_LT(LargestSigmas(parameters, solved.covariance)[0],
            (1.0 - kMinEstimateGain) * LargestSigmas(parameters, held.covariance)[0]);
  // The marginal is the Schur complement: (A - B (D + Sc^-1)^-1 B')^-1.
  const Eigen::MatrixXd& z = solved.information;
  const Eigen::MatrixXd schur = z.topLeftCorner(3, 3) - z.topRightCorner(3, 6) *
                                                            z.bottomRightCorner(6, 6).inverse() *
                                                            z.bottomLeftCorner(6, 3);
  EXPECT_LT((schur.inverse() - solved.covariance).norm(), 1e-9 * solved.covariance.norm());
}

// Point noise alone: the per-edge model adds nothing and the covariance is the plain one.
TEST(EdgePoseSolver, RobotCovarianceMatchesMonteCarloWithPointNoiseOnly) {
  SceneNoise noise;
  noise.point_px = 0.2;
  ExpectCalibrated(RunMonteCarlo(noise, false, 23, true, Handling::kEstimate).unknowns, false,
                   "robot, point noise only");
}

// The base's ROS covariance maps a world twist as finite differences of the base's pose do.
TEST(RosCovariance, MapsTwistsLikeFiniteDifferencesOfTheBasePose) {
  const Eigen::Isometry3d cam_from_world = TestFreePose();
  Eigen::Isometry3d base_from_cam = Eigen::Isometry3d::Identity();
  base_from_cam.linear() =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.2, 1.0, -0.3).normalized()).matrix();
  base_from_cam.translation() << 0.1, -0.05, 1.2;
  auto base_pose = [&](const Eigen::Isometry3d& cam) {
    const Eigen::Isometry3d world_from_base = cam.inverse() * base_from_cam.inverse();
    Eigen::Matrix<double, 6, 1> p;
    p << world_from_base.translation(), RollPitchYaw(world_from_base.linear());
    return p;
  };
  for (int j = 0; j < 6; ++j) {
    WorldTwist v = WorldTwist::Zero();
    v[j] = 1.0;
    const Eigen::Matrix<double, 6, 1> numeric =
        (base_pose(ApplyWorldTwist(cam_from_world, kJacobianStep * v)) -
         base_pose(ApplyWorldTwist(cam_from_world, -kJacobianStep * v))) /
        (2.0 * kJacobianStep);
    const Eigen::Matrix<double, 6, 6> mapped =
        RosBaseCovariance(v * v.transpose(), cam_from_world, base_from_cam);
    EXPECT_LT((mapped - numeric * numeric.transpose()).norm(), 1e-6) << j;
  }
}

}  // namespace
}  // namespace linetrack
