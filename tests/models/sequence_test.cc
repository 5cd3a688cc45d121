// Generated paths and priors: the hall loop stays inside the navigable area, the robot drives at
// the asked speed, the pan-tilt head adds to the base, and the odometry integrates the true
// motion exactly without noise and drifts boundedly with it.
#include "models/render/sequence.h"

#include <gtest/gtest.h>

#include <cmath>

#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack {
namespace {

const std::string kHall = std::string(LINETRACK_SOURCE_DIR) + "/models/hall.cao";

constexpr double kTol = 1e-9;
constexpr double kStepTolM = 1e-3;       // spacing of the resampled loop
constexpr double kMaxDriftShare = 0.06;  // odometry error / distance travelled, with noise

NavigableArea HallArea() {
  NavigableAreaOptions options;
  options.sidecar_path = std::string(LINETRACK_SOURCE_DIR) + "/tests/data/hall.nav.json";
  return NavigableArea::FromModel(WireframeModel::Load(kHall), options);
}

TEST(LoopPath, StaysInsideTheHallAwayFromWalls) {
  const NavigableArea area = HallArea();
  LoopPathOptions options;
  const std::vector<Eigen::Vector2d> loop = LoopInsideArea(area, options);
  ASSERT_GT(loop.size(), 100u);
  EXPECT_GT(Polygon2{loop}.SignedArea(), 0.0);  // counter-clockwise
  double length = 0.0;
  for (size_t i = 0; i < loop.size(); ++i) {
    EXPECT_TRUE(area.Contains(loop[i])) << loop[i].transpose();
    const double step = (loop[(i + 1) % loop.size()] - loop[i]).norm();
    EXPECT_NEAR(step, options.step, kStepTolM);
    length += step;
  }
  // Around the hall (14 m x 9 m) at about 1 m from the walls: 2 (12 + 7) m minus the corners.
  EXPECT_GT(length, 30.0);
  EXPECT_LT(length, 46.0);
  // The loop goes around pillar 1 (the hall's centre): the pillar is inside it.
  EXPECT_TRUE(Polygon2{loop}.Contains({5.0, 4.5}));
}

TEST(LoopPath, FailsWhenNothingFits) {
  LoopPathOptions options;
  options.wall_distance = 6.0;  // more than half the hall's width
  EXPECT_THROW(LoopInsideArea(HallArea(), options), InputError);
}

TEST(DriveAlongLoop, DrivesAtSpeedWithThePanTiltHead) {
  const std::vector<Eigen::Vector2d> loop = LoopInsideArea(HallArea());
  DriveOptions options;
  options.frames = 50;
  options.speed = 0.8;
  options.fps = 8.0;
  options.pan_amplitude = DegToRad(30.0);
  options.tilt_amplitude = DegToRad(3.0);
  const std::vector<SequenceFrame> frames = DriveAlongLoop(loop, options);
  ASSERT_EQ(frames.size(), 50u);
  for (size_t k = 0; k < frames.size(); ++k) {
    const SequenceFrame& f = frames[k];
    EXPECT_NEAR(f.t, k / options.fps, kTol);
    EXPECT_NEAR(WrapAngle(f.camera.heading - f.base.heading - f.pan), 0.0, kTol);
    EXPECT_NEAR(f.pan, options.pan_amplitude * std::sin(2 * kPi * f.t / options.pan_period), kTol);
    EXPECT_NEAR(f.camera.height, options.height, kTol);
    const RobotPose seen = RobotPoseFromCamFromWorld(f.cam_from_world);
    EXPECT_NEAR(seen.tilt, f.camera.tilt, kTol);
    EXPECT_NEAR(WrapAngle(seen.heading - f.camera.heading), 0.0, kTol);
    if (k > 0) {
      const RobotPose& a = frames[k - 1].base;
      // Chord of the arc travelled in one frame; the base drives forward along its heading.
      const Eigen::Vector2d d(f.base.x - a.x, f.base.y - a.y);
      EXPECT_NEAR(d.norm(), options.speed / options.fps, 0.01);
      EXPECT_LT(std::abs(WrapAngle(std::atan2(d.y(), d.x()) - a.heading)), DegToRad(20.0));
    }
  }
  // Default frames: one lap at the asked speed.
  options.frames = 0;
  options.fps = 2.0;
  const size_t lap = DriveAlongLoop(loop, options).size();
  EXPECT_NEAR(lap * options.speed / options.fps, loop.size() * LoopPathOptions().step, 0.5);
}

TEST(Odometry, WithoutNoiseIntegratesTheTrueMotion) {
  DriveOptions drive;
  drive.frames = 200;
  drive.pan_amplitude = DegToRad(20.0);
  const std::vector<SequenceFrame> frames = DriveAlongLoop(LoopInsideArea(HallArea()), drive);
  OdometryOptions exact;
  exact.distance_noise = exact.heading_noise = exact.heading_walk = 0.0;
  exact.scale_bias = exact.heading_bias = 0.0;
  const std::vector<PriorRecord> priors = SimulateOdometryPriors(frames, exact);
  ASSERT_EQ(priors.size(), frames.size());
  for (size_t k = 0; k < frames.size(); ++k) {
    EXPECT_NEAR(priors[k].pose.x, frames[k].base.x, 1e-6);
    EXPECT_NEAR(priors[k].pose.y, frames[k].base.y, 1e-6);
    EXPECT_NEAR(WrapAngle(priors[k].pose.heading - frames[k].camera.heading), 0.0, 1e-9);
    EXPECT_NEAR(priors[k].pose.tilt, frames[k].camera.tilt, kTol);
  }
}

TEST(Odometry, DriftsBoundedlyAndDeterministically) {
  DriveOptions drive;
  drive.frames = 300;  // 15 m at 0.5 m/s and 10 fps
  const std::vector<SequenceFrame> frames = DriveAlongLoop(LoopInsideArea(HallArea()), drive);
  OdometryOptions options;
  options.seed = 5;
  const std::vector<PriorRecord> priors = SimulateOdometryPriors(frames, options);
  double travelled = 0.0, largest = 0.0;
  for (size_t k = 1; k < frames.size(); ++k) {
    travelled += std::hypot(frames[k].base.x - frames[k - 1].base.x,
                            frames[k].base.y - frames[k - 1].base.y);
    largest = std::max(largest, std::hypot(priors[k].pose.x - frames[k].base.x,
                                           priors[k].pose.y - frames[k].base.y));
  }
  EXPECT_GT(largest, 0.005);  // noisy indeed
  EXPECT_LT(largest, kMaxDriftShare * travelled);
  const std::vector<PriorRecord> again = SimulateOdometryPriors(frames, options);
  EXPECT_EQ(again.back().pose.x, priors.back().pose.x);
  options.seed = 6;
  EXPECT_NE(SimulateOdometryPriors(frames, options).back().pose.x, priors.back().pose.x);
}

TEST(FramesFromTrajectory, KeepsTheGivenPoses) {
  const RobotPose pose{3.0, 4.0, DegToRad(75.0), 1.4, DegToRad(6.0)};
  const std::vector<SequenceFrame> frames =
      FramesFromTrajectory({{0.0, CamFromWorld(pose).inverse()}});
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_LT((frames[0].cam_from_world.matrix() - CamFromWorld(pose).matrix()).norm(), kTol);
  EXPECT_NEAR(frames[0].camera.tilt, pose.tilt, kTol);
  EXPECT_NEAR(frames[0].base.heading, pose.heading, kTol);
  const std::vector<StampedPose> truth = GroundTruthPoses(frames);
  EXPECT_LT((truth[0].world_from_cam.matrix() - CamFromWorld(pose).inverse().matrix()).norm(),
            kTol);
}

}  // namespace
}  // namespace linetrack
