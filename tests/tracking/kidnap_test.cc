// The kidnapped robot on a rendered drive of the bundled hall: the robot tracks along the hall
// loop, is lifted and put down on the far side of the hall (its odometry blind to the carry) and
// drives on. The tracking engine must notice that the frames disagree with the carried prior,
// switch to the global mode, find the new pose, confirm it over frames against the odometry, and
// report no wrong `tracking` pose meanwhile. The switch's rule is checked on its own.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "models/navigable_area.h"
#include "models/render/kidnap.h"
#include "models/render/scene_renderer.h"
#include "models/render/sequence.h"
#include "models/view_invariant_regions.h"
#include "tracking/integrity/consistency.h"
#include "tracking/live/tracker_estimator.h"
#include "tracking/tracker/global_recovery.h"
#include "tracking/tracker/tracking_engine.h"

namespace linetrack {
namespace {

constexpr int kFrames = 36;               // 3.6 s at 10 frames/s
constexpr int kKidnapFrame = 12;          // put down on this frame
constexpr int kMaxFramesToTracking = 10;  // from the put-down to a confirmed pose
constexpr double kNearM = 0.10;           // integrity rules: a `tracking` pose beyond is wrong
constexpr double kNearDeg = 2.0;
constexpr double kGlobalPoseM = 0.03;  // the global mode's verified pose against the truth
constexpr double kGlobalPoseDeg = 0.5;
constexpr int kConfirmFrames = 5;  // ReacquisitionCheck::confirm_frames
// The drive without a carry: frames blurred (optical blur, pixels), then covered, from the frame
// of the carry; the pose found again within the frames of issue 14's recovery target.
constexpr double kBlurSigmaPx = 4.0;
constexpr int kBlurredFrames = 4;
constexpr int kCoveredFrames = 6;
constexpr int kMaxFramesToRecover = 5;

const std::string kSource = LINETRACK_SOURCE_DIR;

// The hall loop driven from its start; on kKidnapFrame the robot is put down where the loop is
// half a lap further on, and drives on from there.
struct KidnapDrive {
  WireframeModel model = WireframeModel::Load(kSource + "/models/hall.cao");
  CameraIntrinsics camera = ReadCameraXml(kSource + "/tests/data/camera_wide.xml");
  NavigableArea area = NavigableArea::FromModel(model, AreaOptions());
  std::vector<SequenceFrame> frames;
  std::vector<PriorRecord> priors;
  std::vector<vpImage<unsigned char>> images;

  static NavigableAreaOptions AreaOptions() {
    NavigableAreaOptions nav;
    nav.sidecar_path = kSource + "/tests/data/hall.nav.json";
    return nav;
  }

  // With `carried` false the robot drives on where it is (the same odometry).
  explicit KidnapDrive(bool carried = true) {
    DriveOptions drive;
    drive.tilt = DegToRad(5.0);
    std::vector<SequenceFrame> lap = DriveAlongLoop(LoopInsideArea(area), drive);
    const Pose3Dof put_down = lap[kKidnapFrame + lap.size() / 2].base.Planar();
    lap.resize(kFrames);
    priors = SimulateOdometryPriors(lap, OdometryOptions());
    frames = carried ? ApplyKidnaps(lap, {{kKidnapFrame, put_down}}, &area) : lap;
    RenderOptions render;
    render.scene.clutter = 10;
    SceneRenderer renderer(model, camera, render, &area);
    for (int i = 0; i < kFrames; ++i)
      images.push_back(renderer.Render(frames[i].cam_from_world, i));
  }
};

const KidnapDrive& Drive() {
  static const KidnapDrive drive;
  return drive;
}

std::vector<FrameReport> Replay(const KidnapDrive& d, const TrackingEngineOptions& options) {
  const ViewInvariantRegions regions = ViewInvariantRegions::Build(d.model, d.area);
  TrackingEngine engine({kSource + "/models/hall.cao", &d.model, &regions, &d.area}, d.camera,
                        options);
  std::vector<FrameReport> reports;
  for (int i = 0; i < kFrames; ++i) {
    reports.push_back(engine.Process(d.images[i], d.frames[i].t, RobotReadingOf(d.priors[i].pose)));
  }
  return reports;
}

TrackingEngineOptions EngineOptions() {
  TrackingEngineOptions options;
  options.matcher.noise = DetectedLineNoise();
  return options;
}

// No `tracking` pose beyond its protection levels or the near bounds (docs/integrity.md).
void ExpectNoWrongTrackingPose(const std::vector<FrameReport>& reports, const KidnapDrive& d) {
  for (int i = 0; i < kFrames; ++i) {
    const FrameReport& r = reports[i];
    if (!r.cam_from_world || r.uncertainty.status != IntegrityStatus::kTracking) continue;
    const WorldTwist e = WorldTwistBetween(d.frames[i].cam_from_world, *r.cam_from_world);
    const PoseDifference diff = ComparePoses(*r.cam_from_world, d.frames[i].cam_from_world);
    EXPECT_LE(e.head<2>().norm(), r.uncertainty.protection_position_m) << "frame " << i;
    EXPECT_LE(std::abs(e[5]), r.uncertainty.protection_rotation_rad) << "frame " << i;
    EXPECT_LE(diff.translation, kNearM) << "frame " << i;
    EXPECT_LE(RadToDeg(diff.rotation), kNearDeg) << "frame " << i;
  }
}

TEST(KidnappedRobot, TheGlobalModeFindsTheNewPoseAndConfirmsItWithNoWrongPose) {
  const KidnapDrive& d = Drive();
  const std::vector<FrameReport> reports = Replay(d, EngineOptions());
  for (int i = 0; i < kKidnapFrame; ++i) {
    EXPECT_TRUE(reports[i].cam_from_world.has_value()) << "frame " << i << ": " << reports[i].note;
  }
  // The global pose is followed from the frame it is found on (`global`), and reported only once
  // confirmed (`reported`).
  int global = -1, reported = -1, tracking = -1;
  for (int i = kKidnapFrame; i < kFrames; ++i) {
    const FrameReport& r = reports[i];
    if (global < 0 && r.source == "global" && r.status == TrackStatus::kRelocalised) global = i;
    if (global >= 0 && reported < 0 && r.cam_from_world) reported = i;
    if (tracking < 0 && r.cam_from_world && r.uncertainty.status == IntegrityStatus::kTracking)
      tracking = i;
  }
  std::string trace;  // the frames from the put-down, for a failure's message
  for (int i = kKidnapFrame; i < kFrames; ++i) {
    const FrameReport& r = reports[i];
    trace += "\nframe " + std::to_string(i) + ": " + ToString(r.status) + ", " +
             ToString(r.uncertainty.status) + ", " + r.source + ", " +
             (r.note.empty() ? r.uncertainty.reason : r.note);
  }
  ASSERT_GE(global, kKidnapFrame) << "the global mode found no pose" << trace;
  EXPECT_NE(reports[global].uncertainty.reason.find("global mode"), std::string::npos)
      << reports[global].uncertainty.reason;
  // The frame holds the global pose and not the pose the global mode left, carried by the
  // odometry: the image shows the carry, and that pose is no longer a hypothesis.
  EXPECT_NE(reports[global].uncertainty.reason.find("a carry"), std::string::npos)
      << reports[global].uncertainty.reason;
  EXPECT_FALSE(reports[global].cam_from_world.has_value()) << "an unconfirmed global pose";
  ASSERT_GT(reported, global) << "the global pose was never reported" << trace;
  const PoseDifference found =
      ComparePoses(*reports[reported].cam_from_world, d.frames[reported].cam_from_world);
  EXPECT_LE(found.translation, kGlobalPoseM);
  EXPECT_LE(RadToDeg(found.rotation), kGlobalPoseDeg);
  ASSERT_GE(tracking, global) << "the global pose was never confirmed" << trace;
  EXPECT_LE(tracking - kKidnapFrame, kMaxFramesToTracking) << trace;
  ExpectNoWrongTrackingPose(reports, d);
}

// A global pose the tracker loses before its confirmation and the matcher finds again around it
// is still a global pose: the frames after are withheld until confirm_frames of them are tracked,
// not reported as a re-localisation after a good pose (the global pose was never good).
TEST(KidnappedRobot, AGlobalPoseLostBeforeItsConfirmationIsStillWithheld) {
  const KidnapDrive& d = Drive();
  const std::vector<FrameReport> first = Replay(d, EngineOptions());
  int global = -1;
  for (int i = kKidnapFrame; i < kFrames && global < 0; ++i) {
    if (first[i].source == "global" && first[i].status == TrackStatus::kRelocalised) global = i;
  }
  ASSERT_GE(global, kKidnapFrame) << "the global mode found no pose";
  const int blank = global + 2;  // a covered lens while the global pose is being confirmed
  ASSERT_LT(blank + kConfirmFrames + 1, kFrames);
  KidnapDrive covered = d;
  covered.images[blank] =
      vpImage<unsigned char>(d.images[blank].getHeight(), d.images[blank].getWidth(), 0);
  const std::vector<FrameReport> reports = Replay(covered, EngineOptions());
  EXPECT_FALSE(reports[blank].cam_from_world.has_value()) << reports[blank].note;
  int found_again = -1;
  for (int i = blank + 1; i < kFrames && found_again < 0; ++i) {
    if (reports[i].status == TrackStatus::kRelocalised) found_again = i;
  }
  ASSERT_GT(found_again, blank) << "the pose was not found again after the covered frame";
  // Found again, it is tracked over confirm_frames frames before anything is reported.
  for (int i = found_again; i < std::min(found_again + kConfirmFrames, kFrames); ++i) {
    EXPECT_FALSE(reports[i].cam_from_world.has_value())
        << "frame " << i << ": " << ToString(reports[i].uncertainty.status) << ", "
        << reports[i].source << ", " << reports[i].uncertainty.reason;
  }
  ExpectNoWrongTrackingPose(reports, covered);
}

// The control: without the global mode the engine searches around the carried prior and does
// not find the robot again in the same frames.
TEST(KidnappedRobot, WithoutTheGlobalModeTheRobotIsNotFoundAgain) {
  TrackingEngineOptions options = EngineOptions();
  options.sequence.global.enabled = false;
  const std::vector<FrameReport> reports = Replay(Drive(), options);
  for (int i = kKidnapFrame; i <= kKidnapFrame + kMaxFramesToTracking; ++i) {
    EXPECT_FALSE(reports[i].cam_from_world &&
                 reports[i].uncertainty.status == IntegrityStatus::kTracking)
        << "frame " << i;
  }
  ExpectNoWrongTrackingPose(reports, Drive());
}

// No carry: a stretch of blurred frames, then the lens covered, where the kidnapped drive is
// carried. Frames the matcher cannot place are no evidence of a carry: the engine does not switch
// to the global mode for one, and finds the pose again soon after the view returns, with no wrong
// `tracking` pose.
TEST(KidnappedRobot, BlurredAndCoveredFramesAreNoCarry) {
  KidnapDrive d(/*carried=*/false);
  RenderOptions blurred;
  blurred.scene.clutter = 10;
  blurred.blur_sigma = kBlurSigmaPx;
  SceneRenderer renderer(d.model, d.camera, blurred, &d.area);
  for (int i = kKidnapFrame; i < kKidnapFrame + kBlurredFrames; ++i)
    d.images[i] = renderer.Render(d.frames[i].cam_from_world, i);
  const int first_seen = kKidnapFrame + kBlurredFrames + kCoveredFrames;
  for (int i = kKidnapFrame + kBlurredFrames; i < first_seen; ++i)
    d.images[i] = vpImage<unsigned char>(d.images[i].getHeight(), d.images[i].getWidth(), 0);
  const std::vector<FrameReport> reports = Replay(d, EngineOptions());
  int recovered = -1;
  std::string trace;
  for (int i = kKidnapFrame; i < kFrames; ++i) {
    const FrameReport& r = reports[i];
    const std::string why = r.note + " " + r.uncertainty.reason;
    trace +=
        "\nframe " + std::to_string(i) + ": " + ToString(r.status) + ", " + r.source + ", " + why;
    EXPECT_EQ(why.find("carried away"), std::string::npos) << "frame " << i << ": " << why;
    if (recovered >= 0 || i < first_seen || !r.cam_from_world || r.source == "odometry") continue;
    const PoseDifference e = ComparePoses(*r.cam_from_world, d.frames[i].cam_from_world);
    if (e.translation <= kNearM && RadToDeg(e.rotation) <= kNearDeg) recovered = i;
  }
  ASSERT_GE(recovered, first_seen) << "never found again" << trace;
  EXPECT_LE(recovered - first_seen, kMaxFramesToRecover) << trace;
  ExpectNoWrongTrackingPose(reports, d);
}

TEST(GlobalModeReason, EachTriggerAndItsThreshold) {
  GlobalRecoveryOptions o;
  o.kidnap_s = 0.3;
  o.lost_s = 2.5;
  o.lost_distance_m = 3.0;
  LossState s;
  s.has_prior = false;
  EXPECT_EQ(GlobalModeReason(s, o), "no prior");
  s.has_prior = true;
  s.frame_period_s = 0.1;  // 10 frames/s
  s.frames_since_good = 2;
  s.carry_frames = 2;
  s.driven_since_m = 0.2;
  EXPECT_EQ(GlobalModeReason(s, o), "");
  s.carry_frames = 3;
  EXPECT_NE(GlobalModeReason(s, o).find("carried away: 3 frames"), std::string::npos);
  s.carry_frames = 0;
  s.frames_since_good = 25;
  EXPECT_EQ(GlobalModeReason(s, o), "lost 25 frames (2.5 s)");
  s.frames_since_good = 24;
  s.driven_since_m = 3.0;
  EXPECT_EQ(GlobalModeReason(s, o), "lost over 3.0 m");
  s.driven_since_m = -1.0;  // no odometry: distance says nothing
  EXPECT_EQ(GlobalModeReason(s, o), "");
  o.lost_s = 0.0;  // off
  s.frames_since_good = 1000;
  EXPECT_EQ(GlobalModeReason(s, o), "");
  std::string why;
  o.kidnap_s = -1.0;
  EXPECT_FALSE(o.Check(&why));
}

// The same seconds are more frames at a higher frame rate; no trigger on time before the frames'
// interval is known.
TEST(GlobalModeReason, TheTimesBecomeFramesAtTheFramesRate) {
  EXPECT_EQ(FramesIn(0.3, 0.1), 3);
  EXPECT_EQ(FramesIn(0.3, 1.0 / 30.0), 9);
  EXPECT_EQ(FramesIn(2.5, 0.1), 25);
  EXPECT_EQ(FramesIn(2.5, 0.04), 63);  // 25 frames/s: 2.52 s
  EXPECT_EQ(FramesIn(0.3, 1.0), 1);    // a slow camera: the next frame
  EXPECT_EQ(FramesIn(0.0, 0.1), 0);    // off
  EXPECT_EQ(FramesIn(0.3, 0.0), 0);    // interval not known
  GlobalRecoveryOptions o;
  LossState s;
  s.has_prior = true;
  s.carry_frames = 3;
  s.frame_period_s = 1.0 / 30.0;
  EXPECT_EQ(GlobalModeReason(s, o), "") << "3 frames at 30 frames/s are 0.1 s";
  s.carry_frames = 9;
  EXPECT_NE(GlobalModeReason(s, o).find("carried away"), std::string::npos);
  s.frame_period_s = 0.0;
  EXPECT_EQ(GlobalModeReason(s, o), "");
  // A slow camera: 0.3 s is one frame, but one frame never shows a carry on its own.
  s.frame_period_s = 1.0;
  s.carry_frames = 1;
  EXPECT_EQ(CarryFrames(o, 1.0), 2);
  EXPECT_EQ(GlobalModeReason(s, o), "");
  s.carry_frames = 2;
  EXPECT_NE(GlobalModeReason(s, o).find("carried away"), std::string::npos);
  o.kidnap_s = 0.0;  // off
  EXPECT_EQ(CarryFrames(o, 1.0), 0);
}

// What counts as a frame showing the robot elsewhere: a global pose beyond the rival distance or
// heading from the prior, or an ambiguous view with no rival near it; nothing found says nothing.
TEST(ShowsElsewhere, AFoundPoseOrRivalsAwayFromThePrior) {
  GlobalRecoveryOptions o;  // 0.5 m, 10 deg
  const Pose3Dof prior{2.0, 3.0, DegToRad(90.0)};
  GlobalAttempt a;
  EXPECT_FALSE(ShowsElsewhere(a, prior, o)) << "no answer";
  a.found = true;
  a.planar = {2.3, 3.2, DegToRad(95.0)};  // 0.36 m, 5 deg: the prior's place
  EXPECT_FALSE(ShowsElsewhere(a, prior, o));
  a.planar = {2.0, 3.6, DegToRad(90.0)};  // 0.6 m
  EXPECT_TRUE(ShowsElsewhere(a, prior, o));
  a.planar = {2.0, 3.0, DegToRad(-89.0)};  // the mirror heading, in place
  EXPECT_TRUE(ShowsElsewhere(a, prior, o));
  a.planar = {2.0, 3.0, DegToRad(449.0)};  // 89 deg once wrapped: 1 deg off
  EXPECT_FALSE(ShowsElsewhere(a, prior, o));
  GlobalAttempt ambiguous;
  ambiguous.ambiguous = true;
  ambiguous.rival_poses = {{13.8, 3.0, DegToRad(90.0)}, {2.1, 3.1, DegToRad(92.0)}};
  EXPECT_FALSE(ShowsElsewhere(ambiguous, prior, o)) << "a rival is at the prior";
  ambiguous.rival_poses.pop_back();
  ambiguous.rival_poses.push_back({-9.8, 3.0, DegToRad(90.0)});
  EXPECT_TRUE(ShowsElsewhere(ambiguous, prior, o));
}

}  // namespace
}  // namespace linetrack
