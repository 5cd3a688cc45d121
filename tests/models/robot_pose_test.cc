// The pose conventions of docs/conventions.md, checked on hand-computed cases.
#include "models/robot_pose.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace linetrack
