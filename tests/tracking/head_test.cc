// The simulated head against closed-form motion (latency, acceleration ramps, speed and joint
// limits), and the head kinematics: the forward model against ViSP's, and ViSP's cVe eJe against
// finite differences of the forward model.
#include <gtest/gtest.h>
#include <visp3/robot/vpBiclops.h>
#include <visp3/robot/vpPtu46.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/pan_tilt.h"
#include "tracking/head/head_kinematics.h"
#include "tracking/sim/simulated_head.h"

namespace linetrack {
namespace {

constexpr double kDt = 0.001;           // s, the test's control period
constexpr double kRampTolRad = 2e-3;    // rad: 1 ms sub-steps against the continuous ramp
constexpr double kLimitTolRad = 1e-12;  // rad: joints never pass their limits
constexpr double kRateTol = 1e-9;       // rad/s
constexpr double kJacobianTol = 1e-6;   // finite differences with a 1e-7 step
constexpr double kPoseTol = 1e-6;       // ViSP stores its constants as float

SimulatedHeadOptions TestHead() {
  SimulatedHeadOptions options;
  options.limits = {-1.0, 1.0, -0.5, 0.8, 2.0, 1.5};
  options.max_acceleration = 4.0;
  options.latency_s = 0.05;
  return options;
}

TEST(SimulatedHead, AxisStepRespectsAccelerationAndLimits) {
  AxisMotion axis;
  AxisStep(10.0, 4.0, -1.0, 1.0, 0.01, &axis);
  EXPECT_NEAR(axis.rate, 0.04, kRateTol);  // a dt
  axis = {0.999, 1.0, false};
  AxisStep(1.0, 4.0, -1.0, 1.0, 0.01, &axis);
  EXPECT_EQ(axis.position, 1.0);
  EXPECT_EQ(axis.rate, 0.0);
  EXPECT_TRUE(axis.at_limit);
  EXPECT_NEAR(RateTowards(1.0, 0.0, 0.5, 4.0), 0.5, kRateTol);
  EXPECT_NEAR(RateTowards(0.0, 0.02, 0.5, 4.0), -std::sqrt(2 * 4.0 * 0.02), kRateTol);
}

TEST(SimulatedHead, VelocityCommandAfterLatencyWithARamp) {
  SimulatedHead head(TestHead());
  const double v = 1.0, a = 4.0, latency = 0.05;
  ASSERT_TRUE(head.SetVelocity(v, 0.0).ok());
  head.Step(latency - 2 * kDt);
  HeadState state;
  head.Read(&state);
  EXPECT_EQ(state.pan, 0.0);  // not yet
  head.Step(2 * kDt + 0.5);   // 0.5 s after the command acts
  head.Read(&state);
  // Ramp to v in v/a = 0.25 s, then cruise: x = v (t - v / 2a).
  EXPECT_NEAR(state.pan, v * (0.5 - v / (2 * a)), kRampTolRad);
  EXPECT_NEAR(state.pan_rate, v, kRateTol);
  EXPECT_EQ(state.mode, HeadMode::kVelocity);
  EXPECT_TRUE(state.moving);
  EXPECT_NEAR(state.time_s, latency + 0.5, 1e-9);
}

TEST(SimulatedHead, NeverExceedsSpeedAccelerationOrJointLimits) {
  const SimulatedHeadOptions options = TestHead();
  SimulatedHead head(options);
  head.SetVelocity(50.0, -50.0);  // clamped to 2.0 and -1.5 rad/s
  HeadState previous, state;
  head.Read(&previous);
  bool pan_hit = false, tilt_hit = false;
  for (int i = 0; i < 3000; ++i) {
    if (i == 1500) head.SetVelocity(-50.0, 50.0);
    head.Step(kDt);
    head.Read(&state);
    ASSERT_LE(state.pan, options.limits.pan_max + kLimitTolRad);
    ASSERT_GE(state.pan, options.limits.pan_min - kLimitTolRad);
    ASSERT_LE(state.tilt, options.limits.tilt_max + kLimitTolRad);
    ASSERT_GE(state.tilt, options.limits.tilt_min - kLimitTolRad);
    ASSERT_LE(std::abs(state.pan_rate), options.limits.max_pan_speed + kRateTol);
    ASSERT_LE(std::abs(state.tilt_rate), options.limits.max_tilt_speed + kRateTol);
    // Acceleration bound, except where a joint limit stops the axis dead.
    if (!state.pan_at_limit) {
      ASSERT_LE(std::abs(state.pan_rate - previous.pan_rate),
                options.max_acceleration * kDt + kRateTol);
    }
    pan_hit |= state.pan_at_limit;
    tilt_hit |= state.tilt_at_limit;
    previous = state;
  }
  EXPECT_TRUE(pan_hit);
  EXPECT_TRUE(tilt_hit);
  EXPECT_EQ(state.pan, options.limits.pan_min);  // the second command drove it to the other end
  EXPECT_EQ(state.tilt, options.limits.tilt_max);
  EXPECT_FALSE(state.moving);  // both joints pressed against their limits
}

TEST(SimulatedHead, MoveToSettlesOnTheTarget) {
  SimulatedHead head(TestHead());
  const double pan = 0.6, tilt = -0.3;
  ASSERT_TRUE(head.MoveTo(pan, tilt).ok());
  HeadState state;
  double max_pan = 0.0;
  for (int i = 0; i < 3000; ++i) {
    head.Step(kDt);
    head.Read(&state);
    max_pan = std::max(max_pan, state.pan);
  }
  EXPECT_EQ(state.pan, pan);
  EXPECT_EQ(state.tilt, tilt);
  EXPECT_FALSE(state.moving);
  EXPECT_LE(max_pan, pan + kRampTolRad);  // no real overshoot
  EXPECT_EQ(head.MoveTo(1.5, 0.0).status, HeadStatus::kRejected);
  head.Stop();
  head.Step(0.2);
  head.Read(&state);
  EXPECT_FALSE(state.moving);
}

TEST(SimulatedHead, IsDeterministic) {
  SimulatedHead a(TestHead()), b(TestHead());
  for (SimulatedHead* h : {&a, &b}) {
    h->SetVelocity(0.7, 0.2);
    h->Step(0.123);
    h->MoveTo(-0.4, 0.1);
    h->Step(0.777);
  }
  HeadState sa, sb;
  a.Read(&sa);
  b.Read(&sb);
  EXPECT_EQ(sa.pan, sb.pan);
  EXPECT_EQ(sa.tilt, sb.tilt);
  EXPECT_EQ(sa.pan_rate, sb.pan_rate);
}

TEST(SimulatedHead, BadOptionsAreInputErrors) {
  SimulatedHeadOptions options = TestHead();
  options.max_acceleration = 0.0;
  EXPECT_THROW(SimulatedHead{options}, InputError);
  options = TestHead();
  options.initial_pan = 3.0;
  EXPECT_THROW(SimulatedHead{options}, InputError);
}

TEST(HeadKinematics, ForwardModelFollowsTheConventions) {
  const HeadGeometry centred;  // camera at the axes' crossing
  Eigen::Isometry3d pose = BaseFromCamera(centred, 0.0, 0.0);
  EXPECT_TRUE(pose.linear().col(2).isApprox(Eigen::Vector3d::UnitX()));   // looks forward
  EXPECT_TRUE(pose.linear().col(0).isApprox(-Eigen::Vector3d::UnitY()));  // x to the right
  EXPECT_TRUE(pose.linear().col(1).isApprox(-Eigen::Vector3d::UnitZ()));  // y down
  pose = BaseFromCamera(centred, kPi / 2, 0.0);
  EXPECT_TRUE(pose.linear().col(2).isApprox(Eigen::Vector3d::UnitY()));  // pan is CCW
  const double tilt = DegToRad(20.0);
  pose = BaseFromCamera(centred, 0.0, tilt);
  // docs/conventions.md: optical axis (cos t cos h, cos t sin h, -sin t).
  EXPECT_TRUE(pose.linear().col(2).isApprox(Eigen::Vector3d(std::cos(tilt), 0, -std::sin(tilt))));
}

Eigen::Isometry3d ToEigen(const vpHomogeneousMatrix& m) {
  Eigen::Isometry3d e = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      e.linear()(r, c) = m[r][c];
    e.translation()(r) = m[r][3];
  }
  return e;
}

const double kJoints[][2] = {{0.0, 0.0}, {0.3, 0.2}, {-1.1, -0.4}, {2.5, 0.7}, {-0.2, 0.05}};

TEST(HeadKinematics, ForwardModelMatchesViSP) {
  for (const auto& q : kJoints) {
    vpColVector ptu_q(2), biclops_q(2);
    ptu_q[0] = biclops_q[0] = q[0];
    ptu_q[1] = -q[1];  // vpPtu46 counts tilt upwards
    biclops_q[1] = q[1];
    const Eigen::Isometry3d ptu = ToEigen(vpPtu46().computeMGD(ptu_q));
    const Eigen::Isometry3d biclops = ToEigen(vpBiclops().computeMGD(biclops_q));
    const Eigen::Isometry3d ours_ptu = BaseFromCamera(GeometryOf(HeadModel::kPtu46), q[0], q[1]);
    const Eigen::Isometry3d ours_biclops =
        BaseFromCamera(GeometryOf(HeadModel::kBiclops), q[0], q[1]);
    EXPECT_LT((ptu.matrix() - ours_ptu.matrix()).norm(), kPoseTol) << q[0] << "," << q[1];
    EXPECT_LT((biclops.matrix() - ours_biclops.matrix()).norm(), kPoseTol) << q[0] << "," << q[1];
  }
}

// Camera twist (v, w in the camera frame) of a small joint step, from the forward model.
Eigen::Matrix<double, 6, 1> TwistOfStep(const HeadGeometry& g, double pan, double tilt, double dpan,
                                        double dtilt, double h) {
  const Eigen::Isometry3d c0_from_c1 =
      BaseFromCamera(g, pan, tilt).inverse() * BaseFromCamera(g, pan + dpan, tilt + dtilt);
  const Eigen::AngleAxisd rotation(c0_from_c1.linear());
  Eigen::Matrix<double, 6, 1> twist;
  twist.head<3>() = c0_from_c1.translation() / h;
  twist.tail<3>() = rotation.angle() * rotation.axis() / h;
  return twist;
}

// The nominal geometries and a bracket a few centimetres and degrees off.
std::vector<HeadGeometry> TestGeometries() {
  HeadGeometry off = GeometryOf(HeadModel::kPtu46);
  Eigen::Matrix<double, 6, 1> error;
  error << 0.012, -0.02, 0.007, 0.03, -0.05, 0.04;
  off.tilt_from_camera = MovedPose(off.tilt_from_camera, error);
  return {GeometryOf(HeadModel::kPtu46), GeometryOf(HeadModel::kBiclops), off};
}

TEST(HeadKinematics, ServoJacobianMatchesFiniteDifferences) {
  const double h = 1e-7;
  for (const HeadGeometry& geometry : TestGeometries()) {
    for (const auto& q : kJoints) {
      const Eigen::Matrix<double, 6, 2> J = CameraJacobian(geometry, q[1]);
      const Eigen::Matrix<double, 6, 1> d_pan = TwistOfStep(geometry, q[0], q[1], h, 0.0, h);
      const Eigen::Matrix<double, 6, 1> d_tilt = TwistOfStep(geometry, q[0], q[1], 0.0, h, h);
      EXPECT_LT((J.col(0) - d_pan).norm(), kJacobianTol)
          << "pan column at " << q[0] << "," << q[1] << "\n"
          << J.col(0).transpose() << "\n"
          << d_pan.transpose();
      EXPECT_LT((J.col(1) - d_tilt).norm(), kJacobianTol)
          << "tilt column at " << q[0] << "," << q[1] << "\n"
          << J.col(1).transpose() << "\n"
          << d_tilt.transpose();
    }
  }
  HeadModel parsed;
  EXPECT_TRUE(ParseHeadModel("ptu46", &parsed));
  EXPECT_EQ(parsed, HeadModel::kPtu46);
  EXPECT_FALSE(ParseHeadModel("ptu-d46", &parsed));
}

// The camera Jacobian of the nominal geometries is ViSP's vpPtu46 / vpBiclops cVe eJe (ViSP
// counts the PTU's tilt upwards: its tilt column changes sign).
TEST(HeadKinematics, NominalServoJacobianIsViSPs) {
  for (const auto& q : kJoints) {
    for (HeadModel model : {HeadModel::kPtu46, HeadModel::kBiclops}) {
      const double sign = model == HeadModel::kPtu46 ? -1.0 : 1.0;
      vpColVector visp_q(2);
      visp_q[0] = q[0];
      visp_q[1] = sign * q[1];
      vpMatrix eJe;
      vpVelocityTwistMatrix cVe;
      if (model == HeadModel::kPtu46) {
        vpPtu46().get_eJe(visp_q, eJe);
        vpPtu46().get_cVe(cVe);
      } else {
        vpBiclops().get_eJe(visp_q, eJe);
        vpBiclops().get_cVe(cVe);
      }
      const vpMatrix visp = static_cast<vpMatrix>(cVe) * eJe;
      const Eigen::Matrix<double, 6, 2> ours = CameraJacobian(GeometryOf(model), q[1]);
      for (int r = 0; r < 6; ++r) {
        EXPECT_NEAR(ours(r, 0), visp[r][0], kPoseTol) << "row " << r;
        EXPECT_NEAR(ours(r, 1), sign * visp[r][1], kPoseTol) << "row " << r;
      }
    }
  }
}

TEST(HeadKinematics, GeometryCheckRefusesNonRigidMounts) {
  std::string why;
  EXPECT_TRUE(GeometryOf(HeadModel::kPtu46).Check(&why));
  HeadGeometry g = GeometryOf(HeadModel::kPtu46);
  g.tilt_from_camera.linear() *= 1.01;
  EXPECT_FALSE(g.Check(&why));
  g = GeometryOf(HeadModel::kPtu46);
  g.tilt_from_camera.translation().x() = std::nan("");
  EXPECT_FALSE(g.Check(&why));
  g = GeometryOf(HeadModel::kPtu46);
  g.level_from_base = -Eigen::Matrix3d::Identity();  // a reflection
  EXPECT_FALSE(g.Check(&why));
}

}  // namespace
}  // namespace linetrack
