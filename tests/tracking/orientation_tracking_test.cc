// ViSP's tracker gets the oriented model: the hall and the room written with every face
// reversed, or a seeded half of them, track a short rendered drive with exactly the poses of the
// bundled files.
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

namespace linetrack {
namespace {

constexpr int kFrames = 12;  // 1.2 s at 10 frames/s

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
  EXPECT_TRUE(start.ok) << start.reason;
  for (size_t i = 1; i < images.size(); ++i) {
    const EdgeTrackResult result = tracker.Track(images[i]);
    EXPECT_TRUE(result.ok) << model_path << " frame " << i << ": " << result.reason;
    poses.push_back(result.cam_from_world.matrix());
  }
  return poses;
}

class Tracking : public ::testing::TestWithParam<const char*> {};

TEST_P(Tracking, ReversedFacesTrackExactlyAsWritten) {
  const std::string model_path = kSource + "/models/" + GetParam();
  const WireframeModel model = WireframeModel::Load(model_path);
  CameraIntrinsics camera = ReadCameraXml(kSource + "/tests/data/camera_paper.xml");
  const NavigableArea area = NavigableArea::FromModel(model);
  LoopPathOptions loop;
  loop.wall_distance = 0.8;
  DriveOptions drive;
  drive.frames = kFrames;
  const std::vector<SequenceFrame> frames = DriveAlongLoop(LoopInsideArea(area, loop), drive);
  SceneRenderer renderer(model, camera, RenderOptions());
  std::vector<vpImage<unsigned char>> images;
  for (int i = 0; i < kFrames; ++i)
    images.push_back(renderer.Render(frames[i].cam_from_world, i));

  const CaoModel cao = ReadCao(model_path);
  const std::vector<Eigen::Matrix4d> written = Track(model_path, camera, frames, images);
  for (const auto& [share, seed] : {std::make_pair(1.0, 0u), std::make_pair(0.5, 5u)}) {
    const std::string path =
        WriteReversed(cao, share, seed, std::to_string(seed) + "_" + GetParam());
    const std::vector<Eigen::Matrix4d> reversed = Track(path, camera, frames, images);
    ASSERT_EQ(reversed.size(), written.size());
    for (size_t i = 0; i < written.size(); ++i)
      EXPECT_EQ(reversed[i], written[i]) << "share " << share << ", frame " << i + 1;
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
