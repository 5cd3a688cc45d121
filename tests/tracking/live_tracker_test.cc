// The live loop closed through the tracker (issue 6) on rendered frames of the hall: the
// simulated camera on the simulated head, the moving-edge tracker started and recovered by the
// matcher, the servo. From a 10 deg pan / 5 deg tilt offset the target converges within 2 px of
// the principal point (measured with the true pose); a capped lens while the head turns is
// reported lost, the head stops, and tracking recovers when the lens is uncapped; the target
// stays centred while the robot drives. Wide camera with radial distortion, as the tracker's own
// hall checks use.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "models/geometry.h"
#include "models/navigable_area.h"
#include "models/wireframe.h"
#include "tracking/live/tracker_estimator.h"
#include "tracking/sim/sim_rig.h"
#include "tracking/tracker/tracking_health.h"

namespace linetrack {
namespace {

constexpr double kMaxFinalErrorPx = 2.0;      // the criterion, true pose
constexpr double kMaxConvergenceTimeS = 1.5;  // from 10 deg / 5 deg
constexpr int kMaxRecoveryFrames = 5;         // frames after the lens is uncapped
// Tracked poses while the head slews at up to 0.8 rad/s (1.5 deg per frame): measured 6.7 cm and
// 0.52 deg at worst, on the first frames of the slew; issue 6 bounds a robot without a moving head
// by 2 cm / 0.5 deg. The servo needs the rotation (0.5 deg is 4 px at px = 500).
constexpr double kMaxPositionErrorM = 0.08;
constexpr double kMaxRotationErrorDeg = 1.0;
constexpr double kMaxDriveErrorPx = 4.0;  // while driving, px = 500 (measured 2.1)

const std::string kSource = LINETRACK_SOURCE_DIR;
const Eigen::Vector3d kPillarCorner(9.25, 2.75, 1.5);

struct Hall {
  WireframeModel model = WireframeModel::Load(kSource + "/models/hall.cao");
  CameraIntrinsics camera = ReadCameraXml(kSource + "/tests/data/camera_wide.xml");
  NavigableArea area = [this] {
    NavigableAreaOptions options;
    options.sidecar_path = kSource + "/tests/data/hall.nav.json";
    return NavigableArea::FromModel(model, options);
  }();
};

const Hall& TheHall() {
  static const Hall hall;
  return hall;
}

// The tracker as `linetrack live` builds it: the matcher set for detected lines.
// `image_only`: no coasting on the odometry and no global mode, so that a loss of the image is
// recovered by the matcher and the restart alone.
std::unique_ptr<TrackerPoseEstimator> Tracker(bool image_only) {
  TrackerEstimatorOptions options;
  options.matcher.noise = DetectedLineNoise();
  options.sequence.coast.enabled = !image_only;
  options.sequence.global.enabled = !image_only;
  return std::make_unique<TrackerPoseEstimator>(TheHall().model, TheHall().area, TheHall().camera,
                                                options);
}

struct TrackedRun {
  std::vector<LiveIteration> iterations;
  std::vector<double> true_error_px;
  std::vector<Eigen::Isometry3d> truth;
};

// Runs `frames` frames of the rig (rendered) with the tracker in the loop.
TrackedRun RunWithTracker(const SimCameraOptions& camera, const LiveLoopOptions& loop,
                          const Eigen::Vector2d& start_offset, int frames,
                          bool image_only = false) {
  const std::unique_ptr<TrackerPoseEstimator> tracker = Tracker(image_only);
  SimHeadStart start;
  start.offset_from_target = start_offset;
  SimulatedLiveRig rig(TheHall().model, &TheHall().area, TheHall().camera,
                       SimulatedLiveRigOptions{
                           camera, SimulatedHeadOptions{}, NominalBelief(camera, loop), start, {}},
                       tracker.get());
  TrackedRun run;
  for (int k = 0; k < frames; ++k) {
    run.iterations.push_back(rig.loop().Step());
    run.true_error_px.push_back(rig.TrueErrorPx());
    run.truth.push_back(rig.camera().last_cam_from_world());
  }
  return run;
}

// Every pose the tracker gave after the first (the matcher's) is within the bounds above.
void ExpectAccuratePoses(const TrackedRun& run) {
  for (size_t k = 1; k < run.iterations.size(); ++k) {
    const LiveIteration& it = run.iterations[k];
    if (!it.estimate.has_pose()) continue;
    const PoseDifference d = ComparePoses(*it.estimate.cam_from_world, run.truth[k]);
    EXPECT_LE(d.translation, kMaxPositionErrorM) << "frame " << k;
    EXPECT_LE(RadToDeg(d.rotation), kMaxRotationErrorDeg) << "frame " << k;
  }
}

SimCameraOptions Standing() {
  SimCameraOptions camera;
  camera.path = SimPath::kStill;
  camera.still_base = {3.0, 1.5, DegToRad(20.0)};
  return camera;
}

TEST(LiveWithTracker, ConvergesFromATenByFiveDegreeOffset) {
  LiveLoopOptions loop;
  loop.target = kPillarCorner;
  const TrackedRun run = RunWithTracker(Standing(), loop, {DegToRad(10.0), DegToRad(5.0)}, 75);
  EXPECT_GT(run.true_error_px.front(), 80.0);  // about 99 px at px = 500
  double converged_at = -1.0;
  for (size_t k = 0; k < run.iterations.size(); ++k) {
    const LiveIteration& it = run.iterations[k];
    ASSERT_TRUE(it.estimate.has_pose()) << "frame " << k << ": " << it.estimate.note;
    EXPECT_EQ(it.estimate.source, k == 0 ? "matcher" : "tracker") << "frame " << k;
    if (converged_at < 0.0 && run.true_error_px[k] < kMaxFinalErrorPx) converged_at = it.t;
  }
  EXPECT_GE(converged_at, 0.0);
  EXPECT_LE(converged_at, kMaxConvergenceTimeS);
  for (size_t k = run.iterations.size() - 15; k < run.iterations.size(); ++k) {
    EXPECT_LT(run.true_error_px[k], kMaxFinalErrorPx) << "frame " << k;
  }
  ExpectAccuratePoses(run);
}

TEST(LiveWithTracker, ForcedLossStopsTheHeadAndTrackingRecovers) {
  SimCameraOptions camera = Standing();
  camera.cap_from_s = 0.2;  // while the head still turns towards the target
  camera.cap_to_s = 1.0;
  LiveLoopOptions loop;
  loop.target = kPillarCorner;
  // The loss of the image itself: without coasting (the odometry's pose would stand in) and
  // without the global mode (a lens capped for 25 frames would call it).
  const TrackedRun run =
      RunWithTracker(camera, loop, {DegToRad(10.0), DegToRad(5.0)}, 75, /*image_only=*/true);
  int stops = 0, first_pose_after = -1;
  double capped_pan = std::nan("");
  for (size_t k = 0; k < run.iterations.size(); ++k) {
    const LiveIteration& it = run.iterations[k];
    const bool capped = it.t >= camera.cap_from_s && it.t < camera.cap_to_s;
    if (capped) {
      EXPECT_EQ(it.estimate.status, PoseStatus::kLost) << "frame " << k;
      EXPECT_FALSE(it.estimate.has_pose()) << "frame " << k;
      if (it.command == HeadCommand::kStop) ++stops;
      EXPECT_NE(it.command, HeadCommand::kVelocity) << "frame " << k;
      if (it.t >= camera.cap_from_s + 0.2) {  // latency and deceleration are over
        EXPECT_EQ(it.head.pan_rate, 0.0) << "frame " << k;
        if (std::isnan(capped_pan)) capped_pan = it.head.pan;
        EXPECT_EQ(it.head.pan, capped_pan) << "frame " << k;
      }
    } else if (it.t >= camera.cap_to_s && first_pose_after < 0 && it.estimate.has_pose()) {
      first_pose_after = static_cast<int>(k);
      EXPECT_EQ(it.estimate.status, PoseStatus::kRelocalised);
    }
  }
  EXPECT_EQ(stops, 1);
  const int uncapped = static_cast<int>(std::lround(camera.cap_to_s * camera.fps));
  ASSERT_GE(first_pose_after, uncapped) << "tracking never recovered";
  EXPECT_LT(first_pose_after - uncapped, kMaxRecoveryFrames);
  for (size_t k = first_pose_after; k < run.iterations.size(); ++k) {
    EXPECT_TRUE(run.iterations[k].estimate.has_pose()) << "frame " << k;
  }
  EXPECT_LT(run.true_error_px.back(), kMaxFinalErrorPx);  // servoed again after the loss
  ExpectAccuratePoses(run);
}

TEST(LiveWithTracker, KeepsTheTargetCentredWhileTheRobotDrives) {
  SimCameraOptions camera;
  camera.path = SimPath::kLoop;
  camera.fps = 15.0;
  LiveLoopOptions loop;
  loop.target = Eigen::Vector3d(7.0, 4.5, 1.2);
  const TrackedRun run = RunWithTracker(camera, loop, Eigen::Vector2d::Zero(), 180);  // 12 s, 6 m
  double max_error_px = 0.0;
  for (size_t k = 0; k < run.iterations.size(); ++k) {
    const LiveIteration& it = run.iterations[k];
    EXPECT_TRUE(it.estimate.has_pose()) << "frame " << k << ": " << it.estimate.note;
    if (it.t >= 2.0) max_error_px = std::max(max_error_px, run.true_error_px[k]);
  }
  EXPECT_LE(max_error_px, kMaxDriveErrorPx);
  ExpectAccuratePoses(run);
}

}  // namespace
}  // namespace linetrack
