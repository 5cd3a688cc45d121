// The tracker on visp-images-data mbt/cube (218 real frames of a cube moved by hand), started
// from cube.0.pos with the sample settings: every frame tracked, and the poses agree with ViSP's
// own tracker run beside it from the same start. Agreement is measured where it is observable:
// the reprojection of the cube's corners on faces turned to the camera (a small cube far away is
// nearly affine, so its pose in depth and rotation is weakly determined: a few pixels of
// difference can be 3 cm and 3 degrees). From about frame 187 on, the cube is small and seen at
// an angle where both trackers latch onto texture edges inside its faces and part ways (up to
// 26 px at the visible corners); agreement is asserted up to there (docs/tracking.md).
#include <gtest/gtest.h>
#include <visp3/mbt/vpMbGenericTracker.h>

#include <cstdio>

#include "models/camera.h"
#include "models/wireframe.h"
#include "tests/tracking/visp_data.h"
#include "tracking/tracker/pose_file.h"
#include "tracking/tracker/sequence_tracker.h"

namespace linetrack {
namespace {

using testing::Cube;
using testing::CubeImage;

constexpr int kAgreementFrames = 186;            // frames 0..185, before the two trackers part ways
constexpr double kMaxCornerDifferencePx = 10.0;  // worst visible corner, any of those frames
constexpr double kMeanCornerDifferencePx = 2.5;

// Largest image distance between the two poses' projections of the corners of the faces that
// `reference` sees from the front.
double CornerDifferencePx(const WireframeModel& model, const CameraIntrinsics& camera,
                          const Eigen::Isometry3d& reference, const Eigen::Isometry3d& other) {
  const Eigen::Vector3d centre = reference.inverse().translation();
  double worst = 0.0;
  for (const ModelFace& face : model.faces()) {
    if (face.normal.dot(centre - face.corners[0]) <= 0.0) continue;
    for (const Eigen::Vector3d& corner : face.corners) {
      worst = std::max(
          worst, (camera.Project(reference * corner) - camera.Project(other * corner)).norm());
    }
  }
  return worst;
}

TEST(Cube, EveryFrameTrackedAndAgreesWithVispsOwnTracker) {
  CameraIntrinsics camera = ReadCameraXml(Cube() + "/cube.xml");
  camera.width = 640;
  camera.height = 480;
  TrackerSettings base;
  base.visibility.scanline = false;
  EdgeTracker tracker(Cube() + "/cube.cao", camera,
                      ReadTrackerSettings(Cube() + "/cube.xml", base));
  SequenceTracker sequence(&tracker, camera, nullptr, {});
  const Eigen::Isometry3d start = ReadPoseFile(Cube() + "/cube.0.pos");
  sequence.SetStartPose(start);

  vpMbGenericTracker visp(1, vpMbGenericTracker::EDGE_TRACKER);
  visp.loadConfigFile(Cube() + "/cube.xml", false);
  LoadVispModel(Cube() + "/cube.cao", &visp);

  const WireframeModel model = WireframeModel::Load(Cube() + "/cube.cao");
  double worst_px = 0.0, sum_px = 0.0, worst_centre = 0.0, worst_rotation = 0.0;
  double worst_px_after = 0.0;
  for (int i = 0; i < testing::kCubeFrames; ++i) {
    const vpImage<unsigned char> image = testing::ReadGrey(CubeImage(i));
    const FrameReport report = sequence.Process(image, i / 30.0, std::nullopt);
    if (i == 0) {
      visp.initFromPose(image, ToVispPose(start));
    } else {
      visp.track(image);
    }
    ASSERT_EQ(report.status, TrackStatus::kTracking) << "frame " << i << ": " << report.note;
    if (i == 0) continue;  // ViSP's pose on the start frame is cube.0.pos itself, untracked
    const Eigen::Isometry3d theirs = FromVispPose(visp.getPose());
    const double px = CornerDifferencePx(model, camera, *report.cam_from_world, theirs);
    if (i >= kAgreementFrames) {
      worst_px_after = std::max(worst_px_after, px);
      continue;
    }
    const PoseDifference d = ComparePoses(*report.cam_from_world, theirs);
    worst_px = std::max(worst_px, px);
    sum_px += px;
    worst_centre = std::max(worst_centre, d.translation);
    worst_rotation = std::max(worst_rotation, RadToDeg(d.rotation));
    EXPECT_LE(px, kMaxCornerDifferencePx) << "frame " << i;
  }
  const double mean_px = sum_px / (kAgreementFrames - 1);
  std::printf(
      "frames 1-%d: corners differ by %.2f px at worst, %.2f px on average; camera "
      "centres by %.1f mm, rotations by %.2f deg at worst; frames %d-%d: %.1f px at worst\n",
      kAgreementFrames - 1, worst_px, mean_px, worst_centre * 1e3, worst_rotation, kAgreementFrames,
      testing::kCubeFrames - 1, worst_px_after);
  EXPECT_LE(mean_px, kMeanCornerDifferencePx);
}

}  // namespace
}  // namespace linetrack
