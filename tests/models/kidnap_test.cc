// The kidnapped robot of a rendered drive (models/render/kidnap.h): from the kidnap's frame on the
// truth is the drive moved by one planar rigid motion that puts the base down where asked, so the
// motion between any two later frames is the drive's own; the odometry simulated from the drive
// without the carry sees no jump. Checked on exact synthetic frames.
#include "models/render/kidnap.h"

#include <gtest/gtest.h>

#include <cmath>

#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack {
namespace {

constexpr double kExactM = 1e-9;
constexpr double kExactRad = 1e-9;
constexpr double kOdometryStepM = 0.1;  // a frame's odometry step at 0.5 m/s, 10 frames/s, noisy

// A straight drive along +x at 0.5 m/s and 10 frames/s, the head panned 20 degrees.
std::vector<SequenceFrame> StraightDrive(int count) {
  std::vector<SequenceFrame> frames(count);
  for (int i = 0; i < count; ++i) {
    SequenceFrame& f = frames[i];
    f.t = 0.1 * i;
    f.base = RobotPose{1.0 + 0.05 * i, 2.0, 0.0, 1.3, 0.0};
    f.pan = DegToRad(20.0);
    f.camera = f.base;
    f.camera.heading = f.pan;
    f.camera.tilt = DegToRad(5.0);
    f.cam_from_world = CamFromWorld(f.camera);
  }
  return frames;
}

TEST(Kidnap, TheTruthJumpsToThePutDownAndDrivesOnAsBefore) {
  const std::vector<SequenceFrame> drive = StraightDrive(10);
  const Pose3Dof put_down{6.0, 4.0, DegToRad(90.0)};
  const std::vector<SequenceFrame> kidnapped = ApplyKidnaps(drive, {{4, put_down}}, nullptr);
  for (int i = 0; i < 4; ++i)
    EXPECT_TRUE(kidnapped[i].cam_from_world.isApprox(drive[i].cam_from_world, 1e-15));
  EXPECT_NEAR(kidnapped[4].base.x, 6.0, kExactM);
  EXPECT_NEAR(kidnapped[4].base.y, 4.0, kExactM);
  EXPECT_NEAR(kidnapped[4].base.heading, DegToRad(90.0), kExactRad);
  // The drive goes on along the put-down heading (+y), the head still panned 20 degrees.
  EXPECT_NEAR(kidnapped[9].base.x, 6.0, kExactM);
  EXPECT_NEAR(kidnapped[9].base.y, 4.0 + 0.25, kExactM);
  EXPECT_NEAR(kidnapped[9].camera.heading, DegToRad(110.0), kExactRad);
  // Each camera pose is the one of its moved robot pose, and relative motions are unchanged.
  for (int i = 4; i < 10; ++i) {
    EXPECT_TRUE(kidnapped[i].cam_from_world.isApprox(CamFromWorld(kidnapped[i].camera), 1e-12));
    const Eigen::Isometry3d before = drive[i].cam_from_world * drive[4].cam_from_world.inverse();
    const Eigen::Isometry3d after =
        kidnapped[i].cam_from_world * kidnapped[4].cam_from_world.inverse();
    EXPECT_TRUE(after.isApprox(before, 1e-12)) << "frame " << i;
  }
  // The odometry of the drive without the carry has no jump at the put-down.
  const std::vector<PriorRecord> odometry = SimulateOdometryPriors(drive, OdometryOptions());
  EXPECT_LT(
      std::hypot(odometry[4].pose.x - odometry[3].pose.x, odometry[4].pose.y - odometry[3].pose.y),
      kOdometryStepM);
}

TEST(Kidnap, PlanarCarryTakesOnePoseToTheOther) {
  const Pose3Dof from{1.0, -2.0, 0.3}, to{-4.0, 5.0, 2.5};
  const Eigen::Isometry3d w = PlanarCarry(from, to);
  EXPECT_TRUE(
      (w * Eigen::Vector3d(from.x, from.y, 0.7)).isApprox(Eigen::Vector3d(to.x, to.y, 0.7)));
  const Eigen::Vector3d ahead =
      w * Eigen::Vector3d(from.x + std::cos(from.heading), from.y + std::sin(from.heading), 0.0);
  EXPECT_NEAR(std::atan2(ahead.y() - to.y, ahead.x() - to.x), to.heading, kExactRad);
}

TEST(Kidnap, ParsedFromTheCommandLineFormAndRefusedWhenMalformed) {
  const Kidnap k = ParseKidnap("150:-1.5,2.25,90");
  EXPECT_EQ(k.frame, 150);
  EXPECT_DOUBLE_EQ(k.put_down.x, -1.5);
  EXPECT_DOUBLE_EQ(k.put_down.y, 2.25);
  EXPECT_NEAR(k.put_down.heading, DegToRad(90.0), kExactRad);
  for (const char* bad :
       {"150", "x:1,2,3", "15a:1,2,3", "1:1,2", "1:1,2,3,4", "1:1,2,nan", ":1,2,3"})
    EXPECT_THROW(ParseKidnap(bad), InputError) << bad;
  const std::vector<SequenceFrame> drive = StraightDrive(5);
  EXPECT_THROW(ApplyKidnaps(drive, {{0, {}}}, nullptr), InputError);
  EXPECT_THROW(ApplyKidnaps(drive, {{5, {}}}, nullptr), InputError);
  EXPECT_THROW(ApplyKidnaps(drive, {{3, {}}, {2, {}}}, nullptr), InputError);
}

}  // namespace
}  // namespace linetrack
