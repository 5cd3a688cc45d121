// Coasting on the odometry (tracking/tracker/odometry_coast.h) on exact synthetic drives: a truth
// path, an anchor pose whose errors are exactly at its protection levels and odometry whose
// errors are exactly at (or beyond) the stated bound. The truth must stay within the coasted
// levels while the odometry meets its bound; the levels are reached when every error adds up; an
// odometry beyond its bound takes the truth outside the levels, and the coasting limits make the
// pose lost; contradicting poses are found and their union bound covers the truth.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "models/robot_pose.h"
#include "tracking/integrity/edge_residual.h"
#include "tracking/tracker/odometry_coast.h"

namespace linetrack {
namespace {

constexpr double kStepM = 0.05;          // 0.5 m/s at 10 frames/s
constexpr double kExactTol = 1e-9;       // metres or radians: exact arithmetic
constexpr double kAnchorLevelM = 0.03;   // the anchor's position level
constexpr double kAnchorLevelDeg = 0.5;  // the anchor's heading level
constexpr double kHeight = 1.3, kTiltDeg = 5.0;

RobotPose Camera(double x, double y, double heading) {
  return RobotPose{x, y, heading, kHeight, DegToRad(kTiltDeg), 0.0};
}

// The true camera poses: `steps` steps of kStepM, turning by turns[k] (radians) at step k.
std::vector<RobotPose> TruePath(const std::vector<double>& turns) {
  std::vector<RobotPose> path = {Camera(1.0, 2.0, 0.3)};
  for (double turn : turns) {
    const RobotPose& a = path.back();
    const double heading = a.heading + turn;
    path.push_back(
        Camera(a.x + kStepM * std::cos(a.heading), a.y + kStepM * std::sin(a.heading), heading));
  }
  return path;
}

// Odometry whose every step is off by `factor` x the bound: the step's translation lengthened
// so that its error is factor s |u_o| along the motion, and the heading change by
// factor (h |u_o| + t |turn_o|), in the odometry's own frame from the true first pose.
std::vector<RobotPose> Odometry(const std::vector<RobotPose>& truth, const OdometryBound& bound,
                                double factor) {
  std::vector<RobotPose> odometry = {truth.front()};
  const double s = factor * bound.distance_share;
  for (size_t k = 1; k < truth.size(); ++k) {
    const RobotPose& a = truth[k - 1];
    const RobotPose& b = truth[k];
    // The true step in the base frame at its start.
    const double c = std::cos(a.heading), sn = std::sin(a.heading);
    const double dx = b.x - a.x, dy = b.y - a.y;
    const Eigen::Vector2d u(c * dx + sn * dy, -sn * dx + c * dy);
    const Eigen::Vector2d u_odometry = u / (1.0 - s);  // |u_o - u| = s |u_o|
    const double turn = b.heading - a.heading;
    // turn_o = turn + factor (h |u_o| + t |turn_o|), turn_o >= 0.
    const double turn_odometry = (turn + factor * bound.heading_per_m * u_odometry.norm()) /
                                 (1.0 - factor * bound.turn_share);
    const RobotPose& o = odometry.back();
    const double co = std::cos(o.heading), so = std::sin(o.heading);
    odometry.push_back(Camera(o.x + co * u_odometry.x() - so * u_odometry.y(),
                              o.y + so * u_odometry.x() + co * u_odometry.y(),
                              o.heading + turn_odometry));
  }
  return odometry;
}

// An anchor at the first true pose with errors exactly at its levels: the position off along the
// heading, the heading off by its level in the direction the odometry drifts.
CoastAnchor AnchorAtLevels(const RobotPose& truth, const RobotPose& odometry) {
  const double level_rad = DegToRad(kAnchorLevelDeg);
  const RobotPose estimate =
      Camera(truth.x + kAnchorLevelM * std::cos(truth.heading),
             truth.y + kAnchorLevelM * std::sin(truth.heading), truth.heading + level_rad);
  PoseUncertainty u;
  u.status = IntegrityStatus::kTracking;
  u.world_covariance = Eigen::Matrix<double, 6, 6>::Identity() * 1e-4;
  u.protection_position_m = kAnchorLevelM;
  u.protection_rotation_rad = level_rad;
  return AnchorAtFix(CamFromWorld(estimate), u, odometry, 0);
}

struct CoastError {
  double position_m, rotation_rad;
};

CoastError ErrorOf(const CoastedPose& coasted, const RobotPose& truth) {
  const WorldTwist e = WorldTwistBetween(CamFromWorld(truth), coasted.cam_from_world);
  return {e.head<2>().norm(), std::abs(e[5])};
}

// 40 steps (2 m): straight, a 45 degree turn over 10 steps, straight.
std::vector<double> Turns() {
  std::vector<double> turns(40, 0.0);
  for (int k = 10; k < 20; ++k)
    turns[k] = DegToRad(4.5);
  return turns;
}

TEST(OdometryCoast, AnOdometryAtItsBoundKeepsTheTruthWithinTheLevels) {
  const OdometryBound bound;
  CoastOptions options;
  options.max_frames = 100;
  options.max_distance_m = 10.0;
  const std::vector<RobotPose> truth = TruePath(Turns());
  const std::vector<RobotPose> odometry = Odometry(truth, bound, 1.0);
  CoastAnchor anchor = AnchorAtLevels(truth[0], odometry[0]);
  for (size_t k = 1; k < truth.size(); ++k) {
    const CoastedPose coasted = Coast(anchor, odometry[k], options, IntegrityOptions());
    const CoastError e = ErrorOf(coasted, truth[k]);
    ASSERT_NE(coasted.uncertainty.status, IntegrityStatus::kLost) << "step " << k;
    EXPECT_LE(e.position_m, coasted.uncertainty.protection_position_m + kExactTol) << "step " << k;
    EXPECT_LE(e.rotation_rad, coasted.uncertainty.protection_rotation_rad + kExactTol)
        << "step " << k;
    anchor = coasted.anchor;
  }
}

// Driving straight with no heading error and the position errors all along the motion, the
// error reaches the level exactly: the bound is not loose where nothing else enters.
TEST(OdometryCoast, StraightAlongTheErrorTheLevelIsReachedExactly) {
  OdometryBound bound;
  bound.heading_per_m = 0.0;
  bound.turn_share = 0.0;
  CoastOptions options;
  options.bound = bound;
  const std::vector<RobotPose> truth = TruePath(std::vector<double>(20, 0.0));
  const std::vector<RobotPose> odometry = Odometry(truth, bound, 1.0);
  CoastAnchor anchor = AnchorAtLevels(truth[0], odometry[0]);
  anchor.uncertainty.protection_rotation_rad = 0.0;
  anchor.cam_from_world = CamFromWorld(
      Camera(truth[0].x + kAnchorLevelM * std::cos(truth[0].heading),
             truth[0].y + kAnchorLevelM * std::sin(truth[0].heading), truth[0].heading));
  for (size_t k = 1; k < truth.size(); ++k) {
    const CoastedPose coasted = Coast(anchor, odometry[k], options, IntegrityOptions());
    EXPECT_NEAR(ErrorOf(coasted, truth[k]).position_m, coasted.uncertainty.protection_position_m,
                kExactTol)
        << "step " << k;
    anchor = coasted.anchor;
  }
}

// Twice the bound: the truth leaves the levels within the 2 m; the pose is tracking only while
// its levels are within the alert limits, and lost beyond the coasting limit.
TEST(OdometryCoast, BeyondItsBoundTheTruthLeavesTheLevelsAndTheLimitLosesThePose) {
  const OdometryBound bound;
  CoastOptions options;
  options.max_distance_m = 1.0;
  const IntegrityOptions alert;
  const std::vector<RobotPose> truth = TruePath(Turns());
  const std::vector<RobotPose> odometry = Odometry(truth, bound, 2.0);
  CoastAnchor anchor = AnchorAtLevels(truth[0], odometry[0]);
  bool outside = false;
  for (size_t k = 1; k < truth.size(); ++k) {
    const CoastedPose coasted = Coast(anchor, odometry[k], options, alert);
    const PoseUncertainty& u = coasted.uncertainty;
    const double driven = coasted.anchor.driven_m;
    if (driven > options.max_distance_m) {
      EXPECT_EQ(u.status, IntegrityStatus::kLost) << "step " << k;
      EXPECT_NE(u.reason.find("coasting limit"), std::string::npos) << u.reason;
      continue;
    }
    const CoastError e = ErrorOf(coasted, truth[k]);
    outside = outside || e.position_m > u.protection_position_m ||
              e.rotation_rad > u.protection_rotation_rad;
    const bool within = u.protection_position_m <= alert.alert_position_m &&
                        u.protection_rotation_rad <= alert.alert_rotation_rad;
    EXPECT_EQ(u.status == IntegrityStatus::kTracking, within) << "step " << k;
    anchor = coasted.anchor;
  }
  EXPECT_TRUE(outside) << "an odometry at twice its bound never left the levels";
}

TEST(OdometryCoast, TheLevelsGrowByTheBoundAndTheHeadingLever) {
  const OdometryBound bound{0.1, DegToRad(2.0), 0.2};
  const CoastLevels grown = GrowCoastLevels({0.05, DegToRad(1.0)}, 0.5, DegToRad(-10.0), bound);
  EXPECT_NEAR(grown.position_m, 0.05 + 0.1 * 0.5 + 2.0 * std::sin(DegToRad(0.5)) * 1.1 * 0.5,
              kExactTol);
  EXPECT_NEAR(grown.rotation_rad, DegToRad(1.0 + 2.0 * 0.5 + 0.2 * 10.0), kExactTol);
}

// A heading variance moves into the position across the displacement; the odometry's noise is
// fully correlated along the stretch: n equal steps add (s D / 3)^2, not n (s d / 3)^2.
TEST(OdometryCoast, TheCovarianceCarriesTheHeadingLeverAndCorrelatedNoise) {
  Eigen::Matrix<double, 6, 6> p = Eigen::Matrix<double, 6, 6>::Zero();
  p(5, 5) = 1e-4;
  const Eigen::Matrix<double, 6, 6> carried =
      CarryCovariance(p, Eigen::Vector3d(2.0, 0.0, 0.0), {}, {});
  EXPECT_NEAR(carried(1, 1), 4.0 * 1e-4, kExactTol);
  EXPECT_NEAR(carried(1, 5), 2.0 * 1e-4, kExactTol);
  EXPECT_NEAR(carried(0, 0), 0.0, kExactTol);
  constexpr int kSteps = 10;
  constexpr double kShare = 0.15;
  Eigen::Matrix<double, 6, 6> q = Eigen::Matrix<double, 6, 6>::Zero();
  for (int k = 0; k < kSteps; ++k) {
    q = CarryCovariance(q, Eigen::Vector3d::Zero(), {kShare * kStepM * k, 0.0},
                        {kShare * kStepM * (k + 1), 0.0});
  }
  EXPECT_NEAR(q(0, 0), std::pow(kShare * kStepM * kSteps / 3.0, 2), kExactTol);
}

TEST(OdometryCoast, ContradictingPosesAreFoundAndTheirUnionCoversBoth) {
  PoseUncertainty a, b;
  a.status = b.status = IntegrityStatus::kTracking;
  a.world_covariance = b.world_covariance = Eigen::Matrix<double, 6, 6>::Identity() * 1e-4;
  a.protection_position_m = 0.05;
  b.protection_position_m = 0.08;
  a.protection_rotation_rad = b.protection_rotation_rad = DegToRad(1.0);
  const Eigen::Isometry3d pa = CamFromWorld(Camera(1.0, 1.0, 0.0));
  const Eigen::Isometry3d near = CamFromWorld(Camera(1.12, 1.0, 0.0));
  const Eigen::Isometry3d far = CamFromWorld(Camera(1.14, 1.0, 0.0));
  EXPECT_FALSE(Disagreement(pa, a, near, b).contradicts);
  const PoseDisagreement d = Disagreement(pa, a, far, b);
  ASSERT_TRUE(d.contradicts);
  EXPECT_NEAR(d.position_m, 0.14, kExactTol);
  const PoseUncertainty u = UnionOfContradicting(a, b, d, "faulty");
  EXPECT_EQ(u.status, IntegrityStatus::kDegraded);
  // The truth may be anywhere within b's level of the far pose.
  EXPECT_NEAR(u.protection_position_m, 0.14 + 0.08, kExactTol);
  EXPECT_GE(u.sigma_x_m, 0.14);
  EXPECT_FALSE(PreferCoasted(a, b));  // both tracking: the image pose
  a.status = IntegrityStatus::kDegraded;
  EXPECT_TRUE(PreferCoasted(a, b));
  b.status = IntegrityStatus::kDegraded;
  EXPECT_FALSE(PreferCoasted(a, b));
}

TEST(OdometryCoast, OptionsAreChecked) {
  std::string why;
  EXPECT_TRUE(CoastOptions().Check(&why));
  CoastOptions bad;
  bad.bound.distance_share = 1.0;
  EXPECT_FALSE(bad.Check(&why));
  bad = CoastOptions();
  bad.max_frames = -1;
  EXPECT_FALSE(bad.Check(&why));
}

}  // namespace
}  // namespace linetrack
