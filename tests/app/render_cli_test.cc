// `linetrack render` end to end: one view equals the library's image, a sequence writes frames,
// ground truth, priors and camera, and bad input exits 2 with one line and writes nothing.
#include <gtest/gtest.h>

#include <visp3/io/vpImageIo.h>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "models/render/frame_truth.h"
#include "models/render/scene_renderer.h"
#include "models/trajectory_io.h"
#include "tests/support/cli_test.h"

namespace linetrack {
namespace {

namespace fs = std::filesystem;

const std::string kSource = LINETRACK_SOURCE_DIR;
const std::string kModel = kSource + "/models/hall.cao";
const std::string kCamera = kSource + "/tests/data/camera_paper.xml";
const std::string kNav = kSource + "/tests/data/hall.nav.json";

class RenderCli : public test_support::CliTest {
 protected:
  // Runs `linetrack render` on the hall with the paper's camera and ARGS.
  test_support::CommandRun Render(const std::string& args) const {
    return Linetrack("render --model " + kModel + " --camera " + kCamera + " " + args);
  }

  // Each case (ARGS, what the message must say) exits 2 with one line on stderr.
  void ExpectBadInput(const std::vector<std::pair<std::string, std::string>>& cases) const {
    for (const auto& [args, what] : cases) {
      const test_support::CommandRun run = Render(args);
      EXPECT_EQ(run.code, 2) << args;
      EXPECT_NE(run.err.find(what), std::string::npos) << args << " -> " << run.err;
      EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    }
  }
};

TEST_F(RenderCli, OneViewIsTheLibrarysImage) {
  const std::string out = (dir_ / "view.png").string();
  ASSERT_EQ(Render("--pose 2,2,30 --height 1.3 --tilt 5 --seed 4 --out " + out).code, 0);
  vpImage<unsigned char> written;
  vpImageIo::read(written, out);
  RenderOptions options;
  options.scene.seed = 4;
  SceneRenderer renderer(WireframeModel::Load(kModel), ReadCameraXml(kCamera), options);
  const vpImage<unsigned char> expected =
      renderer.Render(CamFromWorld({2.0, 2.0, DegToRad(30.0), 1.3, DegToRad(5.0)}));
  ASSERT_EQ(written.getWidth(), 640u);
  ASSERT_EQ(written.getHeight(), 480u);
  EXPECT_TRUE(written == expected);
}

TEST_F(RenderCli, SequenceFromATrajectoryWritesEverything) {
  std::vector<StampedPose> poses;
  for (int k = 0; k < 3; ++k) {
    poses.push_back({0.5 * k, CamFromWorld({3.0 + k, 2.0, 0.4 * k, 1.3, DegToRad(4.0)}).inverse()});
  }
  const std::string tum = (dir_ / "in.txt").string();
  std::ofstream(tum) << FormatTum(poses);
  const fs::path out = dir_ / "seq";
  const test_support::CommandRun run = Render("--trajectory " + tum + " --out " + out.string());
  ASSERT_EQ(run.code, 0) << run.err;
  for (const char* name : {"frame_00000.png", "frame_00001.png", "frame_00002.png",
                           "groundtruth.txt", "priors.csv", "camera.xml"}) {
    EXPECT_TRUE(fs::exists(out / name)) << name;
  }
  EXPECT_FALSE(fs::exists(out / "frame_00003.png"));
  const std::vector<StampedPose> truth = ReadTum((out / "groundtruth.txt").string());
  ASSERT_EQ(truth.size(), 3u);
  EXPECT_LT((truth[2].world_from_cam.matrix() - poses[2].world_from_cam.matrix()).norm(), 1e-8);
  const std::vector<PriorRecord> priors = ReadPriors((out / "priors.csv").string());
  ASSERT_EQ(priors.size(), 3u);
  EXPECT_NEAR(priors[0].pose.x, 3.0, 1e-6);  // odometry starts at the true pose
  EXPECT_NEAR(priors[2].pose.tilt, DegToRad(4.0), 1e-6);
  const CameraIntrinsics camera = ReadCameraXml((out / "camera.xml").string());
  EXPECT_EQ(camera.width, 640);
  EXPECT_DOUBLE_EQ(camera.px, 1000.0);
  EXPECT_NE(run.err.find("rendered 3/3 frames"), std::string::npos);  // progress on stderr
}

TEST_F(RenderCli, HallLoopWithPanTilt) {
  const fs::path out = dir_ / "loop";
  const test_support::CommandRun run =
      Render("--path hall-loop --nav " + kNav +
             " --frames 2 --pan-amplitude 20 --clutter 5 --out " + out.string());
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_TRUE(fs::exists(out / "frame_00001.png"));
  EXPECT_EQ(ReadPriors((out / "priors.csv").string()).size(), 2u);
}

TEST_F(RenderCli, WaypointPathWithEffectsWritesTheTruth) {
  const std::string path = (dir_ / "path.csv").string();
  std::ofstream(path) << "# x,y[,heading_deg]\n1,1\n5,1\n5,3,90\n";
  const fs::path out = dir_ / "drive";
  const test_support::CommandRun run = Render(
      "--path " + path + " --nav " + kNav +
      " --frames 12 --speed 0.5 --pan-amplitude 35 --pan-rate 30 --people 1 --blackouts 1 "
      "--blackout-duration 0.2 --exposure-changes 1 --shutter 0.02 --odometry-drift 2.5 --out " +
      out.string());
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find("wrote 12 frames"), std::string::npos) << run.out;
  const std::vector<FrameTruth> truth = ReadFrameTruth((out / "frame_truth.csv").string());
  ASSERT_EQ(truth.size(), 12u);
  EXPECT_EQ(
      std::count_if(truth.begin(), truth.end(), [](const FrameTruth& t) { return t.covered; }), 2);
  EXPECT_NEAR(truth[5].pan_deg, 15.0, 1e-3);  // 0.5 s at 30 deg/s
  const std::string sequence = test_support::ReadAll(out / "sequence.json");
  EXPECT_NE(sequence.find("\"blackouts\""), std::string::npos);
  EXPECT_NE(sequence.find("\"asked_percent\": 2.5"), std::string::npos) << sequence;
  EXPECT_EQ(ReadTum((out / "groundtruth.txt").string()).size(), 12u);
  EXPECT_NEAR(ReadTum((out / "groundtruth.txt").string())[0].world_from_cam.translation().x(), 1.0,
              1e-9);
}

// A kidnap: the truth jumps to the put-down pose, the odometry (priors.csv) does not.
TEST_F(RenderCli, KidnapMovesTheTruthNotTheOdometry) {
  constexpr double kExactM = 1e-6;
  constexpr double kOdometryStepM = 0.2;  // 0.5 m/s at 10 frames/s, with noise: well under
  const fs::path out = dir_ / "kidnap";
  const test_support::CommandRun run = Render(
      "--path hall-loop --nav " + kNav + " --frames 6 --kidnap 3:4,3,90 --out " + out.string());
  ASSERT_EQ(run.code, 0) << run.err;
  const std::vector<StampedPose> truth = ReadTum((out / "groundtruth.txt").string());
  const std::vector<PriorRecord> priors = ReadPriors((out / "priors.csv").string());
  ASSERT_EQ(truth.size(), 6u);
  EXPECT_NEAR(truth[3].world_from_cam.translation().x(), 4.0, kExactM);
  EXPECT_NEAR(truth[3].world_from_cam.translation().y(), 3.0, kExactM);
  EXPECT_GT((truth[3].world_from_cam.translation() - truth[2].world_from_cam.translation()).norm(),
            1.0);
  EXPECT_LT(std::hypot(priors[3].pose.x - priors[2].pose.x, priors[3].pose.y - priors[2].pose.y),
            kOdometryStepM);
  EXPECT_NE(test_support::ReadAll(out / "sequence.json").find("\"kidnaps\""), std::string::npos);
}

TEST_F(RenderCli, FlagsThatCannotApplyAreRefused) {
  const std::string png = (dir_ / "x.png").string();
  const std::string seq = (dir_ / "seq").string();
  const std::string tum = (dir_ / "in.txt").string();
  std::ofstream(tum) << FormatTum({{0.0, CamFromWorld({3.0, 2.0, 0.0, 1.3, 0.0}).inverse()}});
  const std::string path = (dir_ / "path.csv").string();
  std::ofstream(path) << "1,1\n5,1\n";
  const std::string bad = (dir_ / "bad.csv").string();
  std::ofstream(bad) << "1,1\n5;1\n";
  const std::string pillar = (dir_ / "pillar.csv").string();
  std::ofstream(pillar) << "1,4.5\n8,4.5\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--trajectory " + tum + " --pan-amplitude 20 --speed 2 --out " + seq,
       "--speed does not apply to --trajectory"},
      {"--trajectory " + tum + " --height 1.2 --out " + seq, "--height does not apply"},
      {"--pose 1,2,3 --frames 3 --out " + png, "--frames does not apply to one view"},
      {"--pose 1,2,3 --people 1 --out " + png, "--people does not apply"},
      {"--path hall-loop --corner-radius 1 --out " + seq,
       "--corner-radius does not apply to --path hall-loop"},
      {"--path " + path + " --wall-distance 1 --out " + seq, "--wall-distance does not apply"},
      {"--path hall-loop --pan-rate 30 --pan-period 4 --out " + seq, "not both"},
      {"--path " + bad + " --nav " + kNav + " --out " + seq, "bad.csv:2:"},
      {"--path " + path + " --nav " + kNav + " --frames 1000 --out " + seq, "frames at most"},
      {"--path " + pillar + " --nav " + kNav + " --out " + seq, "leaves the navigable area"},
      {"--path " + path + " --nav " + kNav + " --odometry-drift -1 --out " + seq,
       "--odometry-drift"},
  };
  ExpectBadInput(cases);
  EXPECT_FALSE(fs::exists(png));
  EXPECT_FALSE(fs::exists(seq));
}

TEST_F(RenderCli, BadInputExitsTwoWithOneLineAndWritesNothing) {
  const std::string png = (dir_ / "x.png").string();
  const std::string seq = (dir_ / "seq").string();
  const std::string bad_tum = (dir_ / "bad.txt").string();
  std::ofstream(bad_tum) << "0 1 1 1 0 0 0 1\n0.1 1 1 1 0 0 0\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--out " + png, "exactly one of"},
      {"--pose 1,2 --out " + png, "--pose"},
      {"--pose 1,2,3 --out " + (dir_ / "x.jpg").string(), ".png"},
      {"--pose 1,2,3 --noise -1 --out " + png, "noise"},
      {"--pose 1,2,3 --tilt 95 --out " + png, "--tilt"},
      {"--path circle --out " + seq, "neither hall-loop nor a waypoint file"},
      {"--path hall-loop --nav " + kNav + " --speed 0 --out " + seq, "speed"},
      {"--path hall-loop --nav /nonexistent.json --out " + seq, "/nonexistent.json"},
      {"--trajectory " + bad_tum + " --out " + seq, "bad.txt:2:"},
      {"--trajectory /nonexistent.txt --out " + seq, "/nonexistent.txt"},
      {"--path hall-loop --nav " + kNav + " --kidnap 5 --out " + seq, "FRAME:x,y,heading_deg"},
      {"--path hall-loop --nav " + kNav + " --kidnap x:1,2,3 --out " + seq, "not an integer"},
      {"--path hall-loop --nav " + kNav + " --kidnap 5:1,2 --out " + seq, "three finite"},
      {"--path hall-loop --nav " + kNav + " --kidnap 5:1,2,3,4 --out " + seq, "three finite"},
      {"--path hall-loop --nav " + kNav + " --frames 4 --kidnap 9:1,2,3 --out " + seq,
       "the frame must be in [1, 4)"},
      {"--path hall-loop --nav " + kNav + " --frames 4 --kidnap 2:-50,2,0 --out " + seq,
       "leaves the navigable area"},
      {"--pose 1,2,3 --kidnap 2:1,2,3 --out " + png, "--kidnap does not apply"},
  };
  ExpectBadInput(cases);
  EXPECT_FALSE(fs::exists(png));
  EXPECT_FALSE(fs::exists(seq));
}

}  // namespace
}  // namespace linetrack
