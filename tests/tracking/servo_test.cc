// Head pointing and the servo law on exact geometry: the angles that look at a point put it on
// the optical axis; one servo step moves the image error by -lambda e dt through the real head
// kinematics; saturation keeps the direction; rates towards a joint limit shrink to zero; the
// hold at convergence has hysteresis.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/pan_tilt.h"
#include "tracking/head/head_pointing.h"
#include "tracking/servo/head_servo.h"

namespace linetrack {
namespace {

constexpr double kOnAxisTol = 1e-9;         // normalised image coordinates
constexpr double kPoseTol = 1e-9;           // metres, radians
constexpr double kRateTol = 1e-12;          // rad/s
constexpr double kFirstOrderRelTol = 2e-3;  // one step of dt = 1 ms against the linear model
constexpr double kGainTol = 1e-9;

// The paper's synthetic camera: 640x480, px = py = 1000, no distortion.
const CameraIntrinsics& PaperCamera() {
  static const CameraIntrinsics camera =
      ReadCameraXml(std::string(LINETRACK_SOURCE_DIR) + "/tests/data/camera_paper.xml");
  return camera;
}

HeadLimits WideLimits() {
  return {-2.7, 2.7, -0.5, 0.8, 2.0, 2.0};
}

// The nominal geometries, and brackets a few centimetres and degrees off on tilted bases.
std::vector<HeadGeometry> TestGeometries() {
  std::vector<HeadGeometry> geometries = {GeometryOf(HeadModel::kPtu46),
                                          GeometryOf(HeadModel::kBiclops)};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> shift(-0.02, 0.02), turn(-0.08, 0.08), base(-0.03, 0.03);
  for (int k = 0; k < 4; ++k) {
    HeadGeometry g = geometries[k % 2];
    Eigen::Matrix<double, 6, 1> error;
    error << shift(rng), shift(rng), shift(rng), turn(rng), turn(rng), turn(rng);
    g.tilt_from_camera = MovedPose(g.tilt_from_camera, error);
    g.level_from_base = LevelFromBaseRotation(base(rng), base(rng));
    geometries.push_back(g);
  }
  return geometries;
}

TEST(HeadPointing, AnglesLookingAtAPointPutItOnTheOpticalAxis) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> xy(-6.0, 6.0), z(0.0, 3.0), heading(-kPi, kPi);
  for (const HeadGeometry& geometry : TestGeometries()) {
    for (int k = 0; k < 200; ++k) {
      const Pose3Dof base{xy(rng), xy(rng), heading(rng)};
      const Eigen::Vector3d target(xy(rng), xy(rng), z(rng));
      if ((target.head<2>() - Eigen::Vector2d(base.x, base.y)).norm() < 0.5) continue;
      double pan = 0.0, tilt = 0.0;
      ASSERT_TRUE(HeadAnglesLookingAt(geometry, WorldFromHeadBase(geometry, base, 1.2), target,
                                      &pan, &tilt));
      const Eigen::Vector3d seen = CamFromWorldOnHead(geometry, base, 1.2, pan, tilt) * target;
      EXPECT_GT(seen.z(), 0.0);
      EXPECT_NEAR(seen.x() / seen.z(), 0.0, kOnAxisTol);
      EXPECT_NEAR(seen.y() / seen.z(), 0.0, kOnAxisTol);
    }
  }
  // Closer to the pan axis than the PTU's lateral offset: no solution.
  double pan = 0.0, tilt = 0.0;
  const HeadGeometry ptu = GeometryOf(HeadModel::kPtu46);
  EXPECT_FALSE(HeadAnglesLookingAt(ptu, WorldFromHeadBase(ptu, {0.0, 0.0, 0.0}, 1.0),
                                   Eigen::Vector3d(0.05, 0.0, 1.0), &pan, &tilt));
}

TEST(HeadPointing, CameraPoseOnTheHeadFollowsTheConventions) {
  const HeadGeometry ptu = GeometryOf(HeadModel::kPtu46);
  const Pose3Dof base{2.0, 3.0, DegToRad(30.0)};
  const double pan = DegToRad(20.0), tilt = DegToRad(10.0);
  const double crossing = CrossingHeightFor(ptu, 1.3);
  const Eigen::Isometry3d cam_from_world = CamFromWorldOnHead(ptu, base, crossing, pan, tilt);
  const RobotPose pose = CameraPoseOnHead(ptu, base, crossing, pan, tilt);
  // Heading = base heading + pan, tilt = head tilt, and the pose is the same camera.
  EXPECT_NEAR(pose.heading, DegToRad(50.0), kPoseTol);
  EXPECT_NEAR(pose.tilt, tilt, kPoseTol);
  EXPECT_TRUE(CamFromWorld(pose).isApprox(cam_from_world, kPoseTol));
  // Level head: the camera centre is at the requested height, offset_y to the left.
  const RobotPose level = CameraPoseOnHead(ptu, base, crossing, 0.0, 0.0);
  EXPECT_NEAR(level.height, 1.3, kPoseTol);
  const Eigen::Vector2d left(-std::sin(base.heading), std::cos(base.heading));
  EXPECT_NEAR((Eigen::Vector2d(level.x, level.y) - Eigen::Vector2d(base.x, base.y)).dot(left),
              ptu.tilt_from_camera.translation().y(), kPoseTol);
  // The upside-down camera looks the same way.
  const HeadGeometry biclops = GeometryOf(HeadModel::kBiclops);
  EXPECT_NEAR(CameraPoseOnHead(biclops, base, crossing, pan, tilt).heading, DegToRad(50.0),
              kPoseTol);
}

TEST(HeadPointing, AnyMountGivesTheHeadingAndTiltOfItsOpticalAxis) {
  for (const HeadGeometry& geometry : TestGeometries()) {
    const Pose3Dof base{-1.0, 4.0, DegToRad(-75.0)};
    const double crossing = CrossingHeightFor(geometry, 1.4);
    EXPECT_NEAR(CameraPoseOnHead(geometry, base, crossing, 0.0, 0.0).height, 1.4, kPoseTol);
    const double pan = DegToRad(-30.0), tilt = DegToRad(25.0);
    const RobotPose pose = CameraPoseOnHead(geometry, base, crossing, pan, tilt);
    const Eigen::Isometry3d cam_from_world =
        CamFromWorldOnHead(geometry, base, crossing, pan, tilt);
    // The optical axis of the pose agrees with the camera's; the centre is the camera's; with
    // its roll the pose is the camera.
    const Eigen::Vector3d axis = cam_from_world.linear().row(2).transpose();
    EXPECT_LT((CamFromWorld(pose).linear().row(2).transpose() - axis).norm(), kPoseTol);
    EXPECT_LT((CamFromWorld(pose).inverse().translation() - cam_from_world.inverse().translation())
                  .norm(),
              kPoseTol);
    EXPECT_TRUE(CamFromWorld(pose).isApprox(cam_from_world, kPoseTol));
  }
}

TEST(HeadPointing, AMountRolledAboutTheOpticalAxisGivesThatRoll) {
  const Pose3Dof base{1.0, -2.0, DegToRad(40.0)};
  for (double roll_deg : {0.87, -2.0}) {
    HeadGeometry geometry = GeometryOf(HeadModel::kPtu46);
    geometry.tilt_from_camera.rotate(
        Eigen::AngleAxisd(DegToRad(roll_deg), Eigen::Vector3d::UnitZ()));
    const double crossing = CrossingHeightFor(geometry, 1.3);
    for (double tilt_deg : {0.0, 15.0, -10.0}) {
      const RobotPose pose = CameraPoseOnHead(geometry, base, crossing, 0.3, DegToRad(tilt_deg));
      EXPECT_NEAR(pose.roll, DegToRad(roll_deg), kPoseTol);
      EXPECT_NEAR(pose.tilt, DegToRad(tilt_deg), kPoseTol);
    }
  }
  // The upside-down camera is rolled half a turn.
  const HeadGeometry biclops = GeometryOf(HeadModel::kBiclops);
  const RobotPose upside_down = CameraPoseOnHead(biclops, base, 1.2, 0.0, DegToRad(10.0));
  EXPECT_NEAR(std::abs(upside_down.roll), kPi, kPoseTol);
}

TEST(HeadServo, SaturationKeepsTheDirection) {
  bool saturated = true;
  Eigen::Vector2d r = SaturateJointRates({0.3, -0.2}, 1.0, 0.5, &saturated);
  EXPECT_FALSE(saturated);
  EXPECT_EQ(r, Eigen::Vector2d(0.3, -0.2));
  r = SaturateJointRates({3.0, -0.5}, 1.0, 0.5, &saturated);
  EXPECT_TRUE(saturated);
  EXPECT_NEAR(r.x(), 1.0, kRateTol);
  EXPECT_NEAR(r.y(), -0.5 / 3.0, kRateTol);
  r = SaturateJointRates({0.2, -2.0}, 1.0, 0.5, &saturated);
  EXPECT_TRUE(saturated);
  EXPECT_NEAR(r.y(), -0.5, kRateTol);
  EXPECT_NEAR(r.x(), 0.05, kRateTol);
}

TEST(HeadServo, RatesTowardsAJointLimitShrinkToZero) {
  const HeadLimits limits = WideLimits();
  bool limited = false;
  // 0.1 rad from the pan maximum with a 0.25 s horizon: at most 0.4 rad/s towards it.
  Eigen::Vector2d r = KeepWithinJointLimits({1.0, 0.1}, 2.6, 0.0, limits, 0.25, &limited);
  EXPECT_TRUE(limited);
  EXPECT_NEAR(r.x(), 0.4, kRateTol);
  EXPECT_EQ(r.y(), 0.1);
  // Away from the limit: unchanged.
  r = KeepWithinJointLimits({-1.0, 0.1}, 2.6, 0.0, limits, 0.25, &limited);
  EXPECT_FALSE(limited);
  EXPECT_EQ(r.x(), -1.0);
  // At or past a limit: no motion towards it.
  r = KeepWithinJointLimits({1.0, -0.3}, 2.7, -0.5, limits, 0.25, &limited);
  EXPECT_TRUE(limited);
  EXPECT_EQ(r, Eigen::Vector2d(0.0, 0.0));
}

// One servo step through the exact kinematics: after dt the image error is (1 - lambda dt) e.
TEST(HeadServo, OneStepReducesTheErrorAtTheGainThroughTheRealKinematics) {
  const CameraIntrinsics& camera = PaperCamera();
  const std::vector<HeadGeometry> geometries = TestGeometries();
  for (size_t g = 0; g < geometries.size(); ++g) {
    const HeadGeometry& geometry = geometries[g];
    HeadServoOptions options;
    options.geometry = geometry;
    options.target_motion_filter = 0.0;
    options.max_pan_rate = options.max_tilt_rate = 50.0;  // no saturation here
    HeadServo servo(options);
    const Pose3Dof base{1.0, 2.0, DegToRad(15.0)};
    const Eigen::Vector3d target(5.0, 4.0, 0.8);
    double pan0 = 0.0, tilt0 = 0.0;
    ASSERT_TRUE(HeadAnglesLookingAt(geometry, WorldFromHeadBase(geometry, base, 1.2), target, &pan0,
                                    &tilt0));
    const double pan = pan0 + DegToRad(4.0), tilt = tilt0 - DegToRad(2.0);
    const Eigen::Vector2d desired(300.0, 250.0);
    const Eigen::Vector3d seen = CamFromWorldOnHead(geometry, base, 1.2, pan, tilt) * target;
    const ServoStep step =
        servo.Compute(0.0, seen, desired, camera, {pan, tilt, {-3, 3, -1, 1, 100, 100}});
    ASSERT_TRUE(step.ok) << step.reason;
    EXPECT_FALSE(step.converged);
    EXPECT_FALSE(step.saturated);
    const Eigen::Vector2d e0(step.error_u_px, step.error_v_px);
    EXPECT_TRUE(e0.isApprox(camera.Project(seen) - desired, 1e-12));
    EXPECT_GT(e0.norm(), 50.0);
    // The gain is ViSP's adaptive gain at x = |q_dot|_inf / lambda.
    const double x = std::max(std::abs(step.pan_rate), std::abs(step.tilt_rate)) / step.gain;
    const double l0 = options.gain_at_zero, linf = options.gain_at_infinity;
    EXPECT_NEAR(step.gain,
                (l0 - linf) * std::exp(-options.gain_slope_at_zero * x / (l0 - linf)) + linf,
                kGainTol);
    const double dt = 1e-3;
    const Eigen::Vector3d after = CamFromWorldOnHead(geometry, base, 1.2, pan + step.pan_rate * dt,
                                                     tilt + step.tilt_rate * dt) *
                                  target;
    const Eigen::Vector2d e1 = camera.Project(after) - desired;
    const Eigen::Vector2d expected = (1.0 - step.gain * dt) * e0;
    EXPECT_LT((e1 - expected).norm(), kFirstOrderRelTol * (e0 - expected).norm())
        << "geometry " << g;
  }
}

TEST(HeadServo, HoldsAtConvergenceWithHysteresis) {
  const CameraIntrinsics& camera = PaperCamera();
  HeadServoOptions options;
  options.convergence_px = 0.5;
  options.resume_px = 2.0;
  HeadServo servo(options);
  const Eigen::Vector2d desired(320.0, 240.0);
  auto at_pixel_offset = [&](double du) {
    return Eigen::Vector3d(du / camera.px * 4.0, 0.0, 4.0);  // 4 m ahead, du pixels right
  };
  ServoStep s = servo.Compute(0.0, at_pixel_offset(1.0), desired, camera, {0, 0, WideLimits()});
  EXPECT_FALSE(s.converged);  // 1 px > 0.5 px: not converged yet
  EXPECT_NE(s.pan_rate, 0.0);
  s = servo.Compute(0.1, at_pixel_offset(0.2), desired, camera, {0, 0, WideLimits()});
  EXPECT_TRUE(s.converged);
  EXPECT_EQ(s.pan_rate, 0.0);
  EXPECT_EQ(s.tilt_rate, 0.0);
  s = servo.Compute(0.2, at_pixel_offset(1.5), desired, camera, {0, 0, WideLimits()});
  EXPECT_TRUE(s.converged);  // still holding below 2 px
  s = servo.Compute(0.3, at_pixel_offset(3.0), desired, camera, {0, 0, WideLimits()});
  EXPECT_FALSE(s.converged);
  EXPECT_LT(s.pan_rate, 0.0);  // target to the right: pan clockwise (negative)
}

// A target drifting at 60 px/s with the head still: after two frames the estimate of its motion
// feeds forward the rate that follows it, and the servo does not hold on it even at zero error.
TEST(HeadServo, FollowsAMovingTargetInsteadOfHolding) {
  const CameraIntrinsics& camera = PaperCamera();
  HeadServoOptions options;
  options.target_motion_filter = 1.0;  // no smoothing: the estimate is exact after one interval
  HeadServo servo(options);
  const Eigen::Vector2d desired(320.0, 240.0);
  const double speed_px_s = 60.0, dt = 1.0 / 30.0, depth = 4.0;
  auto seen_at = [&](double t) {  // moving right, head fixed at zero
    return Eigen::Vector3d(speed_px_s * t / camera.px * depth, 0.0, depth);
  };
  ServoStep s = servo.Compute(0.0, seen_at(0.0), desired, camera, {0, 0, WideLimits()});
  EXPECT_TRUE(s.converged);  // no motion known yet, error 0
  s = servo.Compute(dt, seen_at(dt), desired, camera, {0, 0, WideLimits()});
  EXPECT_NEAR(s.target_speed_px_s, speed_px_s, 1e-6);
  EXPECT_FALSE(s.converged);
  EXPECT_TRUE(s.compensated);
  // Pan rate that moves the image point left at 60 px/s on its own: -(speed / px) rad/s at
  // zero error, plus the proportional part for the 2 px error.
  const double feed_forward = -speed_px_s / camera.px;
  const double proportional = -s.gain * s.error_u_px / camera.px;
  EXPECT_NEAR(s.pan_rate, feed_forward + proportional, 2e-3 * std::abs(feed_forward));
}

TEST(HeadServo, NoCommandForATargetBehindTheCamera) {
  HeadServo servo(HeadServoOptions{});
  const ServoStep s = servo.Compute(0.0, Eigen::Vector3d(0.0, 0.0, -2.0), {320.0, 240.0},
                                    PaperCamera(), {0.0, 0.0, WideLimits()});
  EXPECT_FALSE(s.ok);
  EXPECT_EQ(s.pan_rate, 0.0);
  EXPECT_NE(s.reason.find("behind"), std::string::npos);
}

TEST(HeadServo, BadOptionsAreInputErrors) {
  HeadServoOptions options;
  options.gain_at_infinity = 10.0;  // above the gain at zero
  EXPECT_THROW(HeadServo{options}, InputError);
  options = {};
  options.resume_px = 0.1;  // below the convergence threshold
  EXPECT_THROW(HeadServo{options}, InputError);
  options = {};
  options.max_pan_rate = 0.0;
  EXPECT_THROW(HeadServo{options}, InputError);
}

}  // namespace
}  // namespace linetrack
