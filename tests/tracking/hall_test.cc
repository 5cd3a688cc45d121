// Tracking that starts and recovers by itself on a rendered sequence of the bundled hall: the
// robot drives the hall loop (wide camera with radial distortion, 10 unmodelled objects, odometry
// priors with drift), the matcher finds the first pose from a prior 0.5 m and 15 degrees off
// (inside the paper's QI3 bounds, 0.75 m / 20 degrees), the moving edges follow; blank or fully
// occluded frames are reported lost, and the pose comes back after them.
#include <gtest/gtest.h>

#include <memory>

#include "matching/lines/line_extractor.h"
#include "models/navigable_area.h"
#include "models/render/scene_renderer.h"
#include "models/render/sequence.h"
#include "models/view_invariant_regions.h"
#include "tracking/tracker/sequence_tracker.h"

namespace linetrack {
namespace {

constexpr int kFrames = 60;      // 6 s at 10 frames/s, 3 m along the loop
constexpr int kHiddenFrom = 20;  // frames kHiddenFrom .. kHiddenFrom + 9 blank or occluded
constexpr int kHiddenFrames = 10;
constexpr int kMaxRecoveryFrames = 5;
constexpr double kMaxPositionErrorM = 0.02;
constexpr double kMaxRotationErrorDeg = 0.5;

const std::string kSource = LINETRACK_SOURCE_DIR;

// The rendered sequence, made once for the whole suite.
struct HallData {
  WireframeModel model = WireframeModel::Load(kSource + "/models/hall.cao");
  CameraIntrinsics camera = ReadCameraXml(kSource + "/tests/data/camera_wide.xml");
  std::vector<SequenceFrame> frames;
  std::vector<PriorRecord> priors;
  std::vector<vpImage<unsigned char>> images;

  HallData() {
    NavigableAreaOptions nav;
    nav.sidecar_path = kSource + "/tests/data/hall.nav.json";
    const NavigableArea area = NavigableArea::FromModel(model, nav);
    DriveOptions drive;
    drive.frames = kFrames;
    frames = DriveAlongLoop(LoopInsideArea(area), drive);
    priors = SimulateOdometryPriors(frames, OdometryOptions());
    RenderOptions render;
    render.scene.clutter = 10;
    SceneRenderer renderer(model, camera, render, &area);
    for (int i = 0; i < kFrames; ++i)
      images.push_back(renderer.Render(frames[i].cam_from_world, i));
  }
};

const HallData& Hall() {
  static const HallData data;
  return data;
}

enum class Hide { kNothing, kBlank, kOccluded };

// A frame that shows nothing of the model: uniform grey, or a close textured occluder (blocks of
// grey levels with strong edges everywhere).
vpImage<unsigned char> HiddenFrame(const vpImage<unsigned char>& like, Hide hide, int index) {
  vpImage<unsigned char> image(like.getHeight(), like.getWidth(), 128);
  if (hide == Hide::kOccluded) {
    for (unsigned v = 0; v < image.getHeight(); ++v) {
      for (unsigned u = 0; u < image.getWidth(); ++u) {
        const unsigned block = (u / 37) * 7919 + (v / 29) * 104729 + index * 13;
        image[v][u] = static_cast<unsigned char>(40 + block % 170);
      }
    }
  }
  return image;
}

struct TrackedRun {
  std::vector<FrameReport> reports;
};

// Tracks the sequence from the QI3-like prior, hiding frames as asked.
TrackedRun TrackHall(Hide hide) {
  const HallData& hall = Hall();
  const NavigableArea area = NavigableArea::FromModel(hall.model);
  const ViewInvariantRegions regions = ViewInvariantRegions::Build(hall.model, area);
  // The matcher set for detected lines, as `linetrack localize --image` and `replay` use it.
  LocalizerOptions matcher;
  matcher.noise = DetectedLineNoise();
  const Localizer localizer(hall.model, &regions, &area, hall.camera, matcher);
  const Relocalizer relocalizer(localizer, MakeLineExtractorFunction(LineExtractionOptions()));
  EdgeTracker tracker(kSource + "/models/hall.cao", hall.camera, TrackerSettings());
  SequenceTracker sequence(&tracker, hall.camera, &relocalizer, {});
  const RobotPose& truth = hall.frames[0].camera;
  sequence.SetInitialPrior(
      Pose3Dof{truth.x + 0.35, truth.y - 0.35, truth.heading + DegToRad(15.0)});
  TrackedRun run;
  for (int i = 0; i < kFrames; ++i) {
    const bool hidden =
        hide != Hide::kNothing && i >= kHiddenFrom && i < kHiddenFrom + kHiddenFrames;
    RobotReading reading;
    reading.odometry = hall.priors[i].pose.Planar();
    reading.height = hall.priors[i].pose.height;
    reading.tilt = hall.priors[i].pose.tilt;
    run.reports.push_back(sequence.Process(
        hidden ? HiddenFrame(hall.images[i], hide, i) : hall.images[i], hall.frames[i].t, reading));
  }
  return run;
}

// Every pose reported is within the bounds of the truth.
void ExpectAccuratePoses(const TrackedRun& run) {
  for (int i = 0; i < kFrames; ++i) {
    const FrameReport& r = run.reports[i];
    if (!r.cam_from_world) continue;
    const PoseDifference d = ComparePoses(*r.cam_from_world, Hall().frames[i].cam_from_world);
    EXPECT_LE(d.translation, kMaxPositionErrorM) << "frame " << i;
    EXPECT_LE(RadToDeg(d.rotation), kMaxRotationErrorDeg) << "frame " << i;
  }
}

TEST(HallSequence, StartedByTheMatcherEveryFrameWithinTwoCentimetresAndHalfADegree) {
  const TrackedRun run = TrackHall(Hide::kNothing);
  EXPECT_EQ(run.reports[0].source, "matcher");
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_TRUE(run.reports[i].cam_from_world.has_value())
        << "frame " << i << ": " << ToString(run.reports[i].status) << ", " << run.reports[i].note;
  }
  ExpectAccuratePoses(run);
}

void ExpectLostThenRecovered(const TrackedRun& run) {
  for (int i = kHiddenFrom; i < kHiddenFrom + kHiddenFrames; ++i) {
    EXPECT_EQ(run.reports[i].status, TrackStatus::kLost) << "frame " << i;
    EXPECT_FALSE(run.reports[i].cam_from_world.has_value()) << "frame " << i;
  }
  const int back = kHiddenFrom + kHiddenFrames;
  int first_pose = -1;
  for (int i = back; i < kFrames && first_pose < 0; ++i) {
    if (run.reports[i].cam_from_world) first_pose = i;
  }
  ASSERT_GE(first_pose, back) << "never recovered";
  EXPECT_LT(first_pose - back, kMaxRecoveryFrames);
  EXPECT_EQ(run.reports[first_pose].status, TrackStatus::kRelocalised);
  for (int i = first_pose; i < kFrames; ++i)
    EXPECT_TRUE(run.reports[i].cam_from_world.has_value()) << "frame " << i;
  for (int i = 0; i < kHiddenFrom; ++i)
    EXPECT_TRUE(run.reports[i].cam_from_world.has_value()) << "frame " << i;
  ExpectAccuratePoses(run);
}

TEST(HallSequence, BlankFramesAreLostAndTheTrackRecovers) {
  ExpectLostThenRecovered(TrackHall(Hide::kBlank));
}

TEST(HallSequence, OccludedFramesAreLostAndTheTrackRecovers) {
  ExpectLostThenRecovered(TrackHall(Hide::kOccluded));
}

}  // namespace
}  // namespace linetrack
