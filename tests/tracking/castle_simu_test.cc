// The tracker on visp-images-data mbt-depth/Castle-simu (40 rendered frames, true poses cMo in
// CameraPose/): started from the first true pose with the sample settings (Config/chateau.xml),
// every frame tracked within 5 mm and 1 degree with the scene model (castle + cube, as ViSP's own
// regression test models the scene). With the castle model alone the edges do not fix the pose
// that well (docs/tracking.md): that case is checked against looser bounds, beside ViSP's own
// tracker on the same frames.
#include <gtest/gtest.h>
#include <visp3/mbt/vpMbGenericTracker.h>

#include <cstdio>

#include "models/camera.h"
#include "tests/tracking/visp_data.h"
#include "tracking/tracker/sequence_tracker.h"

namespace linetrack {
namespace {

using testing::CastleImage;
using testing::CastleSimu;
using testing::CastleTruth;

// The bounds. Translation is checked both as ViSP's regression test measures it (the
// translation of cMo, i.e. the model origin seen from the camera) and as the camera centre.
constexpr double kMaxTranslationErrorM = 0.005;
constexpr double kMaxRotationErrorDeg = 1.0;
// Castle model alone: the worst seen here is 11.9 mm (cMo) and 4.8 degrees; ViSP's bare tracker
// reaches 12.5 mm and 7.6 degrees on the same frames.
constexpr double kAloneMaxTranslationErrorM = 0.015;
constexpr double kAloneMaxRotationErrorDeg = 6.0;
// Frames whose pose the integrity monitor may withhold with the castle alone: where its edges do
// not fix the pose (the tracker still follows them).
constexpr int kAloneMaxWithheldFrames = 2;

struct Worst {
  double object_translation = 0.0;  // |t_cMo - t_cMo_true| (metres)
  double centre_translation = 0.0;  // camera centre distance (metres)
  double rotation_deg = 0.0;
  int tracked = 0;

  void Add(const Eigen::Isometry3d& cam_from_world, const Eigen::Isometry3d& truth) {
    const PoseDifference d = ComparePoses(cam_from_world, truth);
    object_translation =
        std::max(object_translation, (cam_from_world.translation() - truth.translation()).norm());
    centre_translation = std::max(centre_translation, d.translation);
    rotation_deg = std::max(rotation_deg, RadToDeg(d.rotation));
    ++tracked;
  }
};

CameraIntrinsics CastleCamera() {
  CameraIntrinsics camera = ReadCameraXml(CastleSimu() + "/Config/chateau.xml");
  camera.width = 640;
  camera.height = 480;
  return camera;
}

// linetrack over the 40 frames from the first true pose; every frame must be tracked.
Worst TrackCastle(const std::string& model) {
  const CameraIntrinsics camera = CastleCamera();
  TrackerSettings base;
  base.visibility.scanline = false;
  EdgeTracker tracker(model, camera,
                      ReadTrackerSettings(CastleSimu() + "/Config/chateau.xml", base));
  SequenceTracker sequence(&tracker, camera, nullptr, {});
  sequence.SetStartPose(CastleTruth(1));
  Worst worst;
  for (int i = 1; i <= testing::kCastleFrames; ++i) {
    const FrameReport report =
        sequence.Process(testing::ReadGrey(CastleImage(i)), (i - 1) / 30.0, std::nullopt);
    EXPECT_EQ(report.status, TrackStatus::kTracking) << "frame " << i << ": " << report.note;
    if (report.cam_from_world) {
      worst.Add(*report.cam_from_world, CastleTruth(i));
    } else {
      EXPECT_EQ(report.uncertainty.status, IntegrityStatus::kLost) << "frame " << i;
      EXPECT_FALSE(report.uncertainty.reason.empty()) << "frame " << i;
    }
  }
  return worst;
}

// ViSP's own tracker as its samples run it (settings file, model, initFromPose, track()) until
// it throws.
Worst TrackCastleWithVisp(const std::string& model) {
  vpMbGenericTracker visp(1, vpMbGenericTracker::EDGE_TRACKER);
  visp.loadConfigFile(CastleSimu() + "/Config/chateau.xml", false);
  LoadVispModel(model, &visp);
  Worst worst;
  visp.initFromPose(testing::ReadGrey(CastleImage(1)), ToVispPose(CastleTruth(1)));
  for (int i = 2; i <= testing::kCastleFrames; ++i) {
    try {
      visp.track(testing::ReadGrey(CastleImage(i)));
    } catch (const vpException&) {
      break;
    }
    worst.Add(FromVispPose(visp.getPose()), CastleTruth(i));
  }
  return worst;
}

void Report(const char* what, const Worst& w) {
  std::printf(
      "%s: %d frames, worst cMo translation %.2f mm, camera centre %.2f mm, rotation "
      "%.2f deg\n",
      what, w.tracked, w.object_translation * 1e3, w.centre_translation * 1e3, w.rotation_deg);
}

TEST(CastleSimu, SceneModelEveryFrameWithinFiveMillimetresAndOneDegree) {
  const Worst worst = TrackCastle(LINETRACK_SOURCE_DIR "/tests/data/visp/castle_simu_scene.cao");
  Report("linetrack, scene model", worst);
  EXPECT_EQ(worst.tracked, testing::kCastleFrames);
  EXPECT_LE(worst.object_translation, kMaxTranslationErrorM);
  EXPECT_LE(worst.centre_translation, kMaxTranslationErrorM);
  EXPECT_LE(worst.rotation_deg, kMaxRotationErrorDeg);
}

TEST(CastleSimu, CastleModelAloneTracksEveryFrameBetterThanVisp) {
  const std::string model = CastleSimu() + "/Models/chateau.cao";
  const Worst worst = TrackCastle(model);
  const Worst visp = TrackCastleWithVisp(model);
  Report("linetrack, chateau.cao", worst);
  Report("ViSP track(), chateau.cao", visp);
  EXPECT_GE(worst.tracked, testing::kCastleFrames - kAloneMaxWithheldFrames);
  EXPECT_LE(worst.object_translation, kAloneMaxTranslationErrorM);
  EXPECT_LE(worst.rotation_deg, kAloneMaxRotationErrorDeg);
  EXPECT_LT(worst.rotation_deg, visp.rotation_deg);
}

}  // namespace
}  // namespace linetrack
