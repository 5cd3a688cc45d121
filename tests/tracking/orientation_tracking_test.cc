// ViSP's tracker gets the oriented model: the hall and the room written with every face
// reversed, or a seeded half of them, track a short rendered drive with exactly the poses of the
// bundled files, while ViSP given the reversed file as written does not.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "models/cao_reader.h"
#include "models/cao_writer.h"
#include "models/navigable_area.h"
#include "models/render/scene_renderer.h"
#include "models/render/sequence.h"
#include "tests/support/reversed_faces.h"
#include "tracking/tracker/edge_tracker.h"

#include <visp3/core/vpException.h>
#include <visp3/mbt/vpMbGenericTracker.h>

namespace linetrack {
namespace {

// 0.4 s at 50 frames/s: the image moves about 8 pixels a frame, within the moving edges' search
// range (at 10 frames/s, 40 pixels: ViSP, started at the truth, loses even the bundled model).
constexpr int kFrames = 20;
constexpr double kFps = 50.0;
// The translation of the camera-from-world pose within this of the truth (metres).
constexpr double kPositionTolM = 0.05;

const std::string kSource = LINETRACK_SOURCE_DIR;

// Writes `cao` with every face reversed (`share` 1) or a seeded subset, as a file of the test.
std::string WriteReversed(const CaoModel& cao, double share, unsigned seed,
                          const std::string& name) {
  const CaoModel reversed = test_support::ReversedFaces(cao, share, seed);
  const std::string path = ::testing::TempDir() + "linetrack_reversed_" + name;
  std::ofstream(path) << CaoText(reversed, "reversed faces");
  return path;
}

// The poses of EdgeTracker on `images`, started at the true first pose.
std::vector<Eigen::Matrix4d> Track(const std::string& model_path, const CameraIntrinsics& camera,
                                   const std::vector<SequenceFrame>& frames,
                                   const std::vector<vpImage<unsigned char>>& images) {
  EdgeTracker tracker(model_path, camera, TrackerSettings());
  std::vector<Eigen::Matrix4d> poses;
  const EdgeTrackResult start = tracker.Start(images[0], frames[0].cam_from_world);
  EXPECT_TRUE(start.ok) << model_path << ": " << start.reason;
  for (size_t i = 1; i < images.size(); ++i) {
    const EdgeTrackResult result = tracker.Track(images[i]);
    EXPECT_TRUE(result.ok) << model_path << " frame " << i << ": " << result.reason;
    poses.push_back(result.cam_from_world.matrix());
  }
  return poses;
}

// ViSP's own poses on `images` with the file loaded as written (no orientation), started at the
// true first pose; the frames from the first that ViSP loses are missing.
std::vector<Eigen::Matrix4d> TrackAsWritten(const std::string& model_path,
                                            const CameraIntrinsics& camera,
                                            const std::vector<SequenceFrame>& frames,
                                            const std::vector<vpImage<unsigned char>>& images) {
  vpMbGenericTracker tracker(1, vpMbGenericTracker::EDGE_TRACKER);
  ConfigureVispTracker(TrackerSettings(), camera, &tracker);
  LoadVispModel(model_path, &tracker);
  std::vector<Eigen::Matrix4d> poses;
  try {
    tracker.initFromPose(images[0], ToVispPose(frames[0].cam_from_world));
    for (size_t i = 1; i < images.size(); ++i) {
      tracker.track(images[i]);
      poses.push_back(FromVispPose(tracker.getPose()).matrix());
    }
  } catch (const vpException&) {
  }
  return poses;
}

class Tracking : public ::testing::TestWithParam<const char*> {};

TEST_P(Tracking, ReversedFacesTrackExactlyAsWritten) {
  const std::string model_path = kSource + "/models/" + GetParam();
  const WireframeModel model = WireframeModel::Load(model_path);
  // The wide camera of tests/tracking/hall_test.cc without its distortion (the tracker takes
  // undistorted images), no clutter.
  const CameraIntrinsics camera =
      ReadCameraXml(kSource + "/tests/data/camera_wide.xml").Undistorted();
  const NavigableArea area = NavigableArea::FromModel(model);
  DriveOptions drive;
  drive.frames = kFrames;
  drive.fps = kFps;
  const std::vector<SequenceFrame> frames = DriveAlongLoop(LoopInsideArea(area), drive);
  SceneRenderer renderer(model, camera, RenderOptions(), &area);
  std::vector<vpImage<unsigned char>> images;
  for (int i = 0; i < kFrames; ++i)
    images.push_back(renderer.Render(frames[i].cam_from_world, i));

  const CaoModel cao = ReadCao(model_path);
  const std::vector<Eigen::Matrix4d> written = Track(model_path, camera, frames, images);
  // The bundled file tracks: every pose near the truth (the comparison below is not of failures).
  for (size_t i = 0; i < written.size(); ++i) {
    const Eigen::Matrix4d truth = frames[i + 1].cam_from_world.matrix();
    EXPECT_LT((written[i].block<3, 1>(0, 3) - truth.block<3, 1>(0, 3)).norm(), kPositionTolM)
        << "frame " << i + 1;
  }
  for (const auto& [share, seed] : {std::make_pair(1.0, 0u), std::make_pair(0.5, 5u)}) {
    const std::string path =
        WriteReversed(cao, share, seed, std::to_string(seed) + "_" + GetParam());
    const std::vector<Eigen::Matrix4d> reversed = Track(path, camera, frames, images);
    ASSERT_EQ(reversed.size(), written.size());
    for (size_t i = 0; i < written.size(); ++i)
      EXPECT_EQ(reversed[i], written[i]) << "share " << share << ", frame " << i + 1;
    if (share == 1.0) {
      // Without the orientation ViSP sees the reversed walls from behind and culls them: the
      // comparison above can fail.
      const std::vector<Eigen::Matrix4d> original =
          TrackAsWritten(model_path, camera, frames, images);
      const std::vector<Eigen::Matrix4d> culled = TrackAsWritten(path, camera, frames, images);
      ASSERT_EQ(original.size(), written.size());
      EXPECT_NE(culled, original) << "ViSP tracked the reversed file as written like the original";
    }
    std::filesystem::remove(path);
  }
}

INSTANTIATE_TEST_SUITE_P(Models, Tracking, ::testing::Values("hall.cao", "room.cao"),
                         [](const auto& info) {
                           std::string name = info.param;
                           return name.substr(0, name.find('.'));
                         });

}  // namespace
}  // namespace linetrack
