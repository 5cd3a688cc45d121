// The live loop in closed loop on the simulator: renderer-free frames (the pose comes from the
// simulator's truth, so the pixels are not looked at), the simulated head with latency and
// acceleration, the servo. From a 10 deg pan / 5 deg tilt offset the target converges within
// 2 px of the principal point without exceeding joint limits or speeds; the target stays near
// the centre while the robot drives the hall loop; a capped lens stops the head and the servo
// resumes after it. The rendered camera is checked against the renderer and the head.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/navigable_area.h"
#include "models/wireframe.h"
#include "tests/support/ptu_emulator.h"
#include "tracking/head/head_pointing.h"
#include "tracking/head/ptu_driver.h"
#include "tracking/head/ptu_protocol.h"
#include "tracking/live/live_loop.h"
#include "tracking/sim/sim_camera.h"
#include "tracking/sim/sim_rig.h"

namespace linetrack {
namespace {

constexpr double kMaxFinalErrorPx = 2.0;      // the convergence criterion
constexpr double kMaxConvergenceTimeS = 2.0;  // from 10 deg / 5 deg at 30 frames/s
// While the robot drives the loop at 0.5 m/s, after the start: the robot starts mid-turn while the
// head is still, so the first second is a transient (60 px at worst).
constexpr double kSettleS = 2.0;
constexpr double kMaxDriveErrorPx = 8.0;   // measured 6.1 px (corners, head accelerating)
constexpr double kMeanDriveErrorPx = 2.0;  // measured 1.2 px
constexpr double kStopTimeS = 0.2;         // latency + deceleration from 1 rad/s at 6 rad/s^2
constexpr double kRateTol = 1e-9;

const std::string kSource = LINETRACK_SOURCE_DIR;

// The paper's synthetic camera: 640x480, px = py = 1000, no distortion.
const CameraIntrinsics& PaperCamera() {
  static const CameraIntrinsics camera =
      ReadCameraXml(std::string(LINETRACK_SOURCE_DIR) + "/tests/data/camera_paper.xml");
  return camera;
}

const WireframeModel& Hall() {
  static const WireframeModel model = WireframeModel::Load(kSource + "/models/hall.cao");
  return model;
}

const NavigableArea& HallArea() {
  static const NavigableArea area = [] {
    NavigableAreaOptions options;
    options.sidecar_path = kSource + "/tests/data/hall.nav.json";
    return NavigableArea::FromModel(Hall(), options);
  }();
  return area;
}

SimCameraOptions StillBase(const Pose3Dof& base) {
  SimCameraOptions options;
  options.path = SimPath::kStill;
  options.still_base = base;
  options.render = false;
  return options;
}

// The rig of `linetrack live --source sim --head sim` with the head starting `offset` (pan, tilt)
// away from the angles that centre the target.
std::unique_ptr<SimulatedLiveRig> Rig(const SimCameraOptions& camera, const LiveLoopOptions& loop,
                                      double pan_offset, double tilt_offset) {
  SimHeadStart start;
  start.offset_from_target = Eigen::Vector2d(pan_offset, tilt_offset);
  return std::make_unique<SimulatedLiveRig>(
      Hall(), &HallArea(), PaperCamera(),
      SimulatedLiveRigOptions{
          camera, SimulatedHeadOptions{}, NominalBelief(camera, loop), start, {}});
}

// Every frame: joints within their limits, head rates and commands within the maximum speeds.
void ExpectWithinLimits(const LiveIteration& it, const HeadLimits& limits,
                        const HeadServoOptions& servo) {
  EXPECT_TRUE(limits.Contains(it.head.pan, it.head.tilt)) << "frame " << it.frame;
  EXPECT_LE(std::abs(it.head.pan_rate), limits.max_pan_speed + kRateTol) << "frame " << it.frame;
  EXPECT_LE(std::abs(it.head.tilt_rate), limits.max_tilt_speed + kRateTol) << "frame " << it.frame;
  EXPECT_LE(std::abs(it.servo.pan_rate), servo.max_pan_rate + kRateTol) << "frame " << it.frame;
  EXPECT_LE(std::abs(it.servo.tilt_rate), servo.max_tilt_rate + kRateTol) << "frame " << it.frame;
}

const Eigen::Vector3d kPillarCorner(9.25, 2.75, 1.5);  // on the edge of the second pillar

TEST(LiveLoop, ConvergesFromATenByFiveDegreeOffset) {
  const SimCameraOptions camera = StillBase({3.0, 1.5, DegToRad(20.0)});
  LiveLoopOptions options;
  options.target = kPillarCorner;
  auto rig = Rig(camera, options, DegToRad(10.0), DegToRad(5.0));
  LiveSummary summary;
  LiveIteration it;
  double start_error_px = 0.0;
  for (int k = 0; k < 150; ++k) {  // 5 s
    it = rig->loop().Step();
    ASSERT_EQ(it.grab, FrameStatus::kOk);
    ASSERT_TRUE(it.estimate.has_pose());
    ASSERT_TRUE(it.servo.ok) << it.servo.reason;
    ExpectWithinLimits(it, rig->head().Limits(), options.servo);
    summary.Add(it);
    if (k == 0) start_error_px = it.servo.error_px;
  }
  EXPECT_GT(start_error_px, 150.0);  // 10 deg / 5 deg at px = 1000: about 190 px
  EXPECT_GT(summary.max_abs_pan_rate, 0.1);
  EXPECT_GE(summary.first_convergence_t, 0.0);
  EXPECT_LE(summary.first_convergence_t, kMaxConvergenceTimeS);
  EXPECT_LT(it.servo.error_px, kMaxFinalErrorPx);
  EXPECT_LE(summary.max_error_after_convergence_px, kMaxFinalErrorPx);
  EXPECT_TRUE(it.servo.converged);
  EXPECT_EQ(summary.stops, 0);
  EXPECT_EQ(summary.head_errors, 0);
}

TEST(LiveLoop, ConvergesToAChosenPixel) {
  const SimCameraOptions camera = StillBase({3.0, 1.5, DegToRad(20.0)});
  LiveLoopOptions options;
  options.target = kPillarCorner;
  options.desired_px = Eigen::Vector2d(200.0, 300.0);
  auto rig = Rig(camera, options, 0.0, 0.0);
  LiveIteration it;
  for (int k = 0; k < 150; ++k)
    it = rig->loop().Step();
  ASSERT_TRUE(it.servo.ok);
  const Eigen::Vector2d seen =
      PaperCamera().Project(rig->camera().last_cam_from_world() * kPillarCorner);
  EXPECT_LT((seen - Eigen::Vector2d(200.0, 300.0)).norm(), kMaxFinalErrorPx);
}

// Mean and largest distance (pixels) of the target from the desired pixel, truth against truth,
// over one lap of the hall loop after kSettleS, with `servo` options.
struct DriveErrors {
  double mean_px = 0.0, max_px = 0.0, pan_range = 0.0;
};
DriveErrors DriveOneLap(const HeadServoOptions& servo) {
  SimCameraOptions camera;
  camera.path = SimPath::kLoop;
  camera.render = false;
  const Eigen::Vector3d target(7.0, 4.5, 1.2);  // between the pillars, seen from the whole loop
  LiveLoopOptions options;
  options.servo = servo;
  options.target = target;
  auto rig = Rig(camera, options, 0.0, 0.0);  // pointing at the target from the first pose
  LiveSummary summary;
  DriveErrors errors;
  int settled = 0;
  for (int k = 0; k < 76 * 30; ++k) {  // one lap: about 38 m at 0.5 m/s, corners included
    const LiveIteration it = rig->loop().Step();
    EXPECT_TRUE(it.servo.ok) << it.servo.reason;
    ExpectWithinLimits(it, rig->head().Limits(), options.servo);
    summary.Add(it);
    if (it.t < kSettleS) continue;
    const double error_px = rig->TrueErrorPx();
    errors.max_px = std::max(errors.max_px, error_px);
    errors.mean_px += error_px;
    ++settled;
  }
  errors.mean_px /= std::max(settled, 1);
  errors.pan_range = summary.pan_max - summary.pan_min;
  return errors;
}

TEST(LiveLoop, KeepsTheTargetCentredWhileTheRobotDrives) {
  const DriveErrors errors = DriveOneLap(HeadServoOptions{});
  EXPECT_LE(errors.max_px, kMaxDriveErrorPx);
  EXPECT_LE(errors.mean_px, kMeanDriveErrorPx);
  EXPECT_GT(errors.pan_range, 1.0);  // the head turned with the robot
  // The feed-forward of the target's own motion is what keeps it centred: without it the
  // proportional law lags by (image speed) / lambda.
  HeadServoOptions plain;
  plain.target_motion_filter = 0.0;
  const DriveErrors lagging = DriveOneLap(plain);
  EXPECT_GT(lagging.mean_px, 10.0 * errors.mean_px);
}

TEST(LiveLoop, StopsTheHeadWhenThePoseIsLostAndResumesAfter) {
  SimCameraOptions camera = StillBase({3.0, 1.5, DegToRad(20.0)});
  camera.cap_from_s = 0.2;  // while the head is still turning
  camera.cap_to_s = 1.5;
  LiveLoopOptions options;
  options.target = kPillarCorner;
  auto rig = Rig(camera, options, DegToRad(10.0), DegToRad(5.0));
  LiveSummary summary;
  int stops = 0;
  double capped_pan = std::nan("");
  LiveIteration it;
  for (int k = 0; k < 150; ++k) {
    it = rig->loop().Step();
    summary.Add(it);
    const bool capped = it.t >= camera.cap_from_s && it.t < camera.cap_to_s;
    if (!capped) {
      ASSERT_TRUE(it.estimate.has_pose());
      EXPECT_NE(it.command, HeadCommand::kStop);
      continue;
    }
    EXPECT_FALSE(it.estimate.has_pose());
    EXPECT_EQ(it.estimate.status, PoseStatus::kLost);
    EXPECT_FALSE(it.servo.ok);
    if (it.command == HeadCommand::kStop) ++stops;
    EXPECT_TRUE(it.command == HeadCommand::kStop || it.command == HeadCommand::kNone);
    if (it.t >= camera.cap_from_s + kStopTimeS) {
      EXPECT_EQ(it.head.pan_rate, 0.0) << "t " << it.t;
      EXPECT_EQ(it.head.tilt_rate, 0.0) << "t " << it.t;
      if (std::isnan(capped_pan)) capped_pan = it.head.pan;
      EXPECT_EQ(it.head.pan, capped_pan);  // not moving while blind
    }
  }
  EXPECT_EQ(stops, 1);  // one stop, not one per frame
  EXPECT_EQ(summary.losses, 1);
  EXPECT_EQ(summary.recoveries, 1);
  EXPECT_LT(it.servo.error_px, kMaxFinalErrorPx);  // converged again after the cap
  EXPECT_FALSE(std::isnan(capped_pan));
}

// The same loop driving a PTU-D46 through its serial protocol (the emulator on a pseudo-terminal,
// clock advanced one frame period per frame): the servo's rates reach the unit as signed CV
// speeds with the right signs, and the target converges within 2 px despite whole-count speeds.
TEST(LiveLoop, ServosAPtuThroughItsSerialProtocol) {
  std::string why;
  const std::unique_ptr<PtuEmulator> emulator = PtuEmulator::Start({}, &why);
  ASSERT_TRUE(emulator) << why;
  PtuOptions ptu;
  ptu.device = emulator->device_path();
  HeadResult opened;
  const std::unique_ptr<PtuDriver> driver = PtuDriver::Open(ptu, &opened);
  ASSERT_TRUE(driver) << opened.message;

  const SimCameraOptions options = StillBase({3.0, 1.5, DegToRad(20.0)});
  SimulatedCamera camera(Hall(), &HallArea(), PaperCamera(), options);
  double pan = 0.0, tilt = 0.0;
  ASSERT_TRUE(HeadAnglesLookingAt(
      camera.geometry(),
      WorldFromHeadBase(camera.geometry(), camera.BaseAt(0.0), camera.crossing_height()),
      kPillarCorner, &pan, &tilt));
  const double arcsec = driver->unit().pan_resolution_arcsec;
  emulator->SetPositions(std::round(PtuRadiansToCounts(pan + DegToRad(10.0), arcsec, 1)),
                         std::round(PtuRadiansToCounts(tilt + DegToRad(5.0), arcsec, -1)));
  PtuEmulator* unit = emulator.get();
  camera.AttachHead(driver.get(), [unit](double dt) { unit->Advance(dt); });
  SimulatorTruthEstimator truth(&camera);
  LiveLoopOptions loop_options;
  loop_options.target = kPillarCorner;
  loop_options.crossing_height = camera.crossing_height();
  LiveLoop loop(LiveLoopParts{&camera, driver.get(), &truth,
                              [&camera](double t) { return camera.OdometryAt(t); }},
                Hall(), PaperCamera(), loop_options);
  LiveIteration it;
  double start_error_px = 0.0, late_max_error_px = 0.0;
  for (int k = 0; k < 150; ++k) {  // 5 s
    it = loop.Step();
    ASSERT_EQ(it.grab, FrameStatus::kOk) << camera.LastError();
    ASSERT_TRUE(it.servo.ok) << it.servo.reason;
    EXPECT_TRUE(it.command == HeadCommand::kNone || it.command_result.ok())
        << it.command_result.message;
    const double error_px =
        (PaperCamera().Project(camera.last_cam_from_world() * kPillarCorner) - loop.desired_px())
            .norm();
    if (k == 0) start_error_px = error_px;
    if (it.t >= 4.0) late_max_error_px = std::max(late_max_error_px, error_px);
  }
  EXPECT_GT(start_error_px, 150.0);
  EXPECT_LT(late_max_error_px, kMaxFinalErrorPx);
  ASSERT_TRUE(loop.SafeStop().ok());
  const std::vector<std::string> sent = emulator->commands();
  // The first servo command turns right (negative pan counts) and up (positive tilt counts on a
  // D46): the start was 10 deg left of and 5 deg below the target.
  const auto velocity_mode = std::find(sent.begin(), sent.end(), "CV");
  auto first_speed = [&](const char* axis) {
    for (auto c = velocity_mode; c != sent.end(); ++c) {
      if (c->rfind(axis, 0) == 0 && c->size() > 2 && *c != std::string(axis) + "0") {
        return std::stol(c->substr(2));
      }
    }
    return 0L;
  };
  ASSERT_NE(velocity_mode, sent.end());
  EXPECT_LT(first_speed("PS"), 0L);
  EXPECT_GT(first_speed("TS"), 0L);
  EXPECT_EQ(sent.back(), "TS0");  // the safe stop: H PS0 TS0
}

// A simulated head that refuses velocity commands on demand (a unit answering "!").
class RefusingHead : public PanTiltHead {
 public:
  explicit RefusingHead(SimulatedHead* head) : head_(head) {}
  std::string Describe() const override { return "refusing " + head_->Describe(); }
  HeadLimits Limits() const override { return head_->Limits(); }
  HeadResult Read(HeadState* state) override { return head_->Read(state); }
  HeadResult MoveTo(double pan, double tilt) override { return head_->MoveTo(pan, tilt); }
  HeadResult SetVelocity(double pan_rate, double tilt_rate) override {
    if (refuse) return HeadResult::Error(HeadStatus::kRejected, "Illegal Command");
    return head_->SetVelocity(pan_rate, tilt_rate);
  }
  HeadResult Stop() override { return head_->Stop(); }
  bool refuse = false;

 private:
  SimulatedHead* head_;
};

// A refused velocity command must not leave the head running on the previous one.
TEST(LiveLoop, StopsTheHeadWhenAVelocityCommandIsRefused) {
  const SimCameraOptions options = StillBase({3.0, 1.5, DegToRad(20.0)});
  SimulatedCamera camera(Hall(), &HallArea(), PaperCamera(), options);
  double pan = 0.0, tilt = 0.0;
  ASSERT_TRUE(HeadAnglesLookingAt(
      camera.geometry(),
      WorldFromHeadBase(camera.geometry(), camera.BaseAt(0.0), camera.crossing_height()),
      kPillarCorner, &pan, &tilt));
  SimulatedHeadOptions head_options;
  head_options.initial_pan = pan + DegToRad(10.0);
  SimulatedHead sim_head(head_options);
  RefusingHead head(&sim_head);
  camera.AttachHead(&sim_head);
  SimulatorTruthEstimator truth(&camera);
  LiveLoopOptions loop_options;
  loop_options.target = kPillarCorner;
  loop_options.crossing_height = camera.crossing_height();
  LiveLoop loop(
      LiveLoopParts{&camera, &head, &truth, [&camera](double t) { return camera.OdometryAt(t); }},
      Hall(), PaperCamera(), loop_options);
  for (int k = 0; k < 5; ++k)
    ASSERT_EQ(loop.Step().command, HeadCommand::kVelocity);  // turning
  head.refuse = true;
  const LiveIteration refused = loop.Step();
  EXPECT_TRUE(refused.head_error);
  EXPECT_EQ(refused.command, HeadCommand::kStop);
  EXPECT_TRUE(refused.command_result.ok());
  EXPECT_NE(refused.note.find("Illegal Command"), std::string::npos) << refused.note;
  for (int k = 0; k < 15; ++k)
    loop.Step();  // 0.5 s: latency and deceleration are over
  HeadState state;
  ASSERT_TRUE(sim_head.Read(&state).ok());
  EXPECT_EQ(state.pan_rate, 0.0);
  EXPECT_EQ(state.tilt_rate, 0.0);
}

TEST(LiveLoop, TargetDefaultsToTheCentroidOfTheVisibleModel) {
  const SimCameraOptions camera = StillBase({3.0, 1.5, DegToRad(20.0)});
  SimulatedLiveRig rig(
      Hall(), &HallArea(), PaperCamera(),
      SimulatedLiveRigOptions{
          camera, SimulatedHeadOptions{}, NominalBelief(camera, LiveLoopOptions{}), {}, {}});
  const LiveIteration first = rig.loop().Step();
  ASSERT_TRUE(first.has_target);
  ASSERT_TRUE(rig.loop().target().has_value());
  // A convex combination of points inside the view frustum projects inside the image.
  const Eigen::Vector3d seen = rig.camera().last_cam_from_world() * *rig.loop().target();
  EXPECT_GT(seen.z(), 0.0);
  EXPECT_TRUE(PaperCamera().Contains(PaperCamera().Project(seen)));
  const OcclusionTester occlusion(Hall());
  const auto again =
      VisibleModelCentroid(Hall(), occlusion, rig.camera().last_cam_from_world(), PaperCamera());
  ASSERT_TRUE(again.has_value());
  EXPECT_TRUE(again->isApprox(*rig.loop().target(), 1e-12));
  LiveIteration it;
  for (int k = 0; k < 90; ++k)
    it = rig.loop().Step();
  EXPECT_TRUE(it.target.isApprox(first.target, 1e-12));  // fixed after the first pose
  EXPECT_LT(it.servo.error_px, kMaxFinalErrorPx);
}

TEST(SimulatedCamera, RendersTheViewOfTheHeadAndStepsIt) {
  SimCameraOptions options = StillBase({3.0, 1.5, DegToRad(20.0)});
  options.render = true;
  options.fps = 10.0;
  SimulatedHead head;
  Frame frame;
  SimulatedCamera camera(Hall(), &HallArea(), PaperCamera(), options);
  EXPECT_EQ(camera.Grab(&frame), FrameStatus::kDeviceLost);  // no head yet
  EXPECT_FALSE(camera.LastError().empty());
  camera.AttachHead(&head);
  ASSERT_EQ(camera.Grab(&frame), FrameStatus::kOk);
  EXPECT_EQ(frame.timestamp_s, 0.0);
  SceneRenderer renderer(Hall(), PaperCamera(), options.render_options, &HallArea());
  const Eigen::Isometry3d pose0 = CamFromWorldOnHead(
      GeometryOf(HeadModel::kPtu46), options.still_base, camera.crossing_height(), 0.0, 0.0);
  EXPECT_TRUE(camera.last_cam_from_world().isApprox(pose0, 1e-12));
  EXPECT_TRUE(frame.image == renderer.Render(pose0, 0));
  // A pan command acts after the head's latency; the next frame is one period later.
  ASSERT_TRUE(head.SetVelocity(0.5, 0.0).ok());
  ASSERT_EQ(camera.Grab(&frame), FrameStatus::kOk);
  EXPECT_NEAR(frame.timestamp_s, 0.1, 1e-12);
  EXPECT_NEAR(head.time(), 0.1, 1e-9);
  EXPECT_GT(camera.last_pan(), 0.0);
  const Eigen::Isometry3d pose1 =
      CamFromWorldOnHead(GeometryOf(HeadModel::kPtu46), options.still_base,
                         camera.crossing_height(), camera.last_pan(), camera.last_tilt());
  EXPECT_TRUE(camera.last_cam_from_world().isApprox(pose1, 1e-12));
  EXPECT_TRUE(frame.image == renderer.Render(pose1, 1));
  EXPECT_FALSE(frame.image == renderer.Render(pose0, 1));
}

TEST(SimulatedCamera, ParsesItsArguments) {
  SimCameraOptions options;
  ParseSimArguments("path=loop,fps=15,speed=0.3,seed=4,clutter=3,noise=1,blur=0,cap=2-3.5,render=0",
                    &options);
  EXPECT_EQ(options.path, SimPath::kLoop);
  EXPECT_EQ(options.fps, 15.0);
  EXPECT_EQ(options.speed, 0.3);
  EXPECT_EQ(options.render_options.scene.seed, 4u);
  EXPECT_EQ(options.odometry_seed, 4u);
  EXPECT_EQ(options.render_options.scene.clutter, 3);
  EXPECT_EQ(options.render_options.noise_sigma, 1.0);
  EXPECT_EQ(options.render_options.blur_sigma, 0.0);
  EXPECT_EQ(options.cap_from_s, 2.0);
  EXPECT_EQ(options.cap_to_s, 3.5);
  EXPECT_FALSE(options.render);
  for (const char* bad : {"path=spiral", "fps=0", "fps=abc", "cap=3-2", "cap=3", "wobble=1",
                          "seed=-1", "render=yes", "fps"}) {
    SimCameraOptions o;
    try {
      ParseSimArguments(bad, &o);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--source sim:"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace linetrack
