// The pose conventions of docs/conventions.md, checked on hand-computed cases.
#include "models/robot_pose.h"

#include <gtest/gtest.h>

#include <cmath>

#include "models/geometry.h"

namespace linetrack {
namespace {

constexpr double kTol = 1e-12;

TEST(RobotPose, LevelCameraLooksAlongHeading) {
  // Heading 90 deg: the optical axis is world +y, the camera x axis world +x... (r = (sin h, -cos
  // h, 0)).
  const RobotPose pose{1.0, 2.0, DegToRad(90.0), 1.5, 0.0};
  const Eigen::Isometry3d cam_from_world = CamFromWorld(pose);
  const Eigen::Vector3d ahead = cam_from_world * Eigen::Vector3d(1.0, 7.0, 1.5);
  EXPECT_NEAR(ahead.x(), 0.0, kTol);
  EXPECT_NEAR(ahead.y(), 0.0, kTol);
  EXPECT_NEAR(ahead.z(), 5.0, kTol);
  const Eigen::Vector3d right = cam_from_world * Eigen::Vector3d(2.0, 3.0, 1.5);
  EXPECT_NEAR(right.x(), 1.0, kTol);  // world +x is to the camera's right when facing +y
  const Eigen::Vector3d above = cam_from_world * Eigen::Vector3d(1.0, 3.0, 2.5);
  EXPECT_NEAR(above.y(), -1.0, kTol);  // camera y points down
}

TEST(RobotPose, PositiveTiltLooksDown) {
  const RobotPose pose{0.0, 0.0, 0.0, 1.0, DegToRad(45.0)};
  const Eigen::Vector3d floor_point = CamFromWorld(pose) * Eigen::Vector3d(1.0, 0.0, 0.0);
  EXPECT_NEAR(floor_point.x(), 0.0, kTol);
  EXPECT_NEAR(floor_point.y(), 0.0, kTol);  // on the optical axis
  EXPECT_NEAR(floor_point.z(), std::sqrt(2.0), kTol);
}

TEST(RobotPose, RoundTripThroughCamFromWorld) {
  const RobotPose pose{3.2, -1.1, DegToRad(-130.0), 1.27, DegToRad(12.0)};
  const RobotPose back = RobotPoseFromCamFromWorld(CamFromWorld(pose));
  EXPECT_NEAR(back.x, pose.x, kTol);
  EXPECT_NEAR(back.y, pose.y, kTol);
  EXPECT_NEAR(back.height, pose.height, kTol);
  EXPECT_NEAR(WrapAngle(back.heading - pose.heading), 0.0, kTol);
  EXPECT_NEAR(back.tilt, pose.tilt, kTol);
  EXPECT_NEAR(RollOf(CamFromWorld(pose)), 0.0, kTol);
}

TEST(RobotPose, LevelFrameUndoesTheTilt) {
  const double tilt = DegToRad(17.0);
  const RobotPose tilted{0.0, 0.0, 0.3, 1.0, tilt};
  const RobotPose level{0.0, 0.0, 0.3, 1.0, 0.0};
  const Eigen::Vector3d p(4.0, 2.0, 0.2);
  const Eigen::Vector3d in_tilted = CamFromWorld(tilted) * p;
  const Eigen::Vector3d in_level = CamFromWorld(level) * p;
  EXPECT_LT((LevelFromCam(tilt) * in_tilted - in_level).norm(), kTol);
}

TEST(RobotPose, RollTurnsTheImageAboutTheOpticalAxis) {
  // A camera rolled by +roll about its optical axis sees a point that the unrolled camera sees at
  // normalised (x, y) at Rz(-roll) (x, y): image x turned towards image y.
  const double roll = DegToRad(7.0);
  const RobotPose unrolled{0.4, -1.2, DegToRad(35.0), 1.3, DegToRad(14.0)};
  RobotPose rolled = unrolled;
  rolled.roll = roll;
  const Eigen::Vector3d p(5.0, 2.5, 2.1);
  const Eigen::Vector3d a = CamFromWorld(unrolled) * p;
  const Eigen::Vector3d b = CamFromWorld(rolled) * p;
  EXPECT_NEAR(b.z(), a.z(), kTol);  // the optical axis is the same
  const Eigen::Vector2d seen_unrolled(a.x() / a.z(), a.y() / a.z());
  const Eigen::Vector2d seen_rolled(b.x() / b.z(), b.y() / b.z());
  EXPECT_LT((UnrollImagePoint(seen_rolled, roll) - seen_unrolled).norm(), kTol);
  EXPECT_LT((Eigen::Rotation2Dd(-roll) * seen_unrolled - seen_rolled).norm(), kTol);
  // The rolled camera's x axis rises out of the horizontal for a negative roll.
  const Eigen::Matrix3d r = CamFromWorldRotation(unrolled.heading, unrolled.tilt, -roll);
  EXPECT_NEAR(r(0, 2), std::sin(roll) * std::cos(unrolled.tilt), kTol);
  EXPECT_LT((r * r.transpose() - Eigen::Matrix3d::Identity()).norm(), kTol);
  EXPECT_NEAR(r.determinant(), 1.0, kTol);
}

TEST(RobotPose, RoundTripWithRoll) {
  for (double roll_deg : {-30.0, -0.87, 0.0, 2.5, 60.0}) {
    for (double tilt_deg : {-40.0, 0.0, 25.0}) {
      const RobotPose pose{-2.0, 0.7, DegToRad(170.0), 1.1, DegToRad(tilt_deg), DegToRad(roll_deg)};
      const Eigen::Isometry3d cam_from_world = CamFromWorld(pose);
      const RobotPose back = RobotPoseFromCamFromWorld(cam_from_world);
      EXPECT_NEAR(back.x, pose.x, kTol);
      EXPECT_NEAR(back.y, pose.y, kTol);
      EXPECT_NEAR(back.height, pose.height, kTol);
      EXPECT_NEAR(WrapAngle(back.heading - pose.heading), 0.0, kTol);
      EXPECT_NEAR(back.tilt, pose.tilt, kTol);
      EXPECT_NEAR(back.roll, pose.roll, kTol);
      EXPECT_NEAR(RollOf(cam_from_world), pose.roll, kTol);
      // The heading is the optical axis' direction on the floor, whatever the roll.
      const Eigen::Vector3d f = cam_from_world.linear().row(2).transpose();
      EXPECT_NEAR(WrapAngle(std::atan2(f.y(), f.x()) - pose.heading), 0.0, kTol);
    }
  }
}

}  // namespace
}  // namespace linetrack
