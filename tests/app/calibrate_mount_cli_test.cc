// `linetrack calibrate-mount` end to end: rendered views of a board with a known mount and floor
// (tests/support/mount_scene.h) calibrated from files; bad input (an image missing from
// ANGLES.csv, one head angle, turns about one axis, no board) exits 2 with one line and writes
// nothing; the live mode on the simulator with its bracket off; and `live --mount` using the
// result.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "models/camera.h"
#include "models/geometry.h"
#include "models/pan_tilt.h"
#include "tests/support/cli_test.h"
#include "tests/support/mount_scene.h"

namespace linetrack {
namespace {

namespace fs = std::filesystem;
using test_support::CliTest;
using test_support::CommandRun;
using test_support::MountScene;

constexpr double kMountPositionTolM = 1e-3;
constexpr double kMountRotationTolDeg = 0.1;
constexpr double kFloorHeightTolM = 2e-3;
// The simulator's renderer (2 x 2 supersampling, blur, noise, lit hall) is rougher than the
// ray-cast boards: the live mode is held to 2 mm and 0.2 deg.
constexpr double kSimPositionTolM = 2e-3;
constexpr double kSimRotationTolDeg = 0.2;

const std::string kSource = LINETRACK_SOURCE_DIR;
const std::string kBoardFlags = " --pattern chessboard --cols 9 --rows 6 --square 0.04";

Eigen::Isometry3d MatrixOf(const nlohmann::json& values) {
  Eigen::Matrix4d m;
  for (int k = 0; k < 16; ++k)
    m(k / 4, k % 4) = values.at(static_cast<size_t>(k)).get<double>();
  Eigen::Isometry3d t;
  t.matrix() = m;
  return t;
}

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// The scene of seed 3 rendered once per process (ctest runs each test in its own process, two at
// a time) into views/view_NN.png, floor.png, angles.csv (with the floor's row) and camera.xml;
// bad input is tried on blank views of the same size, which the checks refuse quickly.
class CalibrateMountCli : public CliTest {
 protected:
  static void SetUpTestSuite() {
    scene_ = test_support::MakeMountScene(3);
    shared_ = fs::path(LINETRACK_BINARY_DIR) / "test_output" /
              ("CalibrateMountCli.shared." + std::to_string(::getpid()));
  }
  static void TearDownTestSuite() { fs::remove_all(shared_); }

  // The rendered views (made on first use).
  static const fs::path& Rendered() {
    if (fs::exists(shared_ / "angles.csv")) return shared_;
    fs::create_directories(shared_ / "views");
    BoardRenderOptions render;
    render.blur_sigma = 0.6;
    render.noise_sigma = 2.0;
    cv::Mat floor;
    const std::vector<cv::Mat> views = test_support::RenderMountViews(scene_, render, &floor);
    std::ofstream angles(shared_ / "angles.csv.partial");
    angles << "image,pan_deg,tilt_deg\n";
    for (size_t i = 0; i < views.size(); ++i) {
      const std::string name = "view_" + std::to_string(100 + i).substr(1) + ".png";
      cv::imwrite((shared_ / "views" / name).string(), views[i]);
      angles << name << "," << RadToDeg(scene_.angles[i].pan) << ","
             << RadToDeg(scene_.angles[i].tilt) << "\n";
    }
    cv::imwrite((shared_ / "floor.png").string(), floor);
    angles << "floor.png," << RadToDeg(scene_.floor_angles.pan) << ","
           << RadToDeg(scene_.floor_angles.tilt) << "\n";
    angles.close();
    WriteCameraXml((shared_ / "camera.xml").string(), scene_.camera);
    fs::rename(shared_ / "angles.csv.partial", shared_ / "angles.csv");
    return shared_;
  }

  // `count` blank views view_NN.png and the scene's camera.xml in dir_/blank.
  fs::path Blank(int count) const {
    const fs::path blank = dir_ / "blank";
    fs::create_directories(blank);
    const cv::Mat grey(scene_.camera.height, scene_.camera.width, CV_8U, cv::Scalar(128));
    for (int i = 0; i < count; ++i)
      cv::imwrite((blank / ("view_" + std::to_string(100 + i).substr(1) + ".png")).string(), grey);
    WriteCameraXml((blank / "camera.xml").string(), scene_.camera);
    return blank;
  }

  static std::string FileFlags(const fs::path& folder, const std::string& angles) {
    const std::string views = fs::exists(folder / "views") ? "views/view_*.png" : "view_*.png";
    return " --images '" + (folder / views).string() + "' --angles " + angles + " --camera " +
           (folder / "camera.xml").string() + kBoardFlags;
  }

  // A copy of angles.csv with every row's angles replaced by `pan(i)`, `tilt(i)`.
  template <typename Pan, typename Tilt>
  std::string Angles(const std::string& name, Pan pan, Tilt tilt, int rows) const {
    const fs::path path = dir_ / name;
    std::ofstream out(path);
    out << "image,pan_deg,tilt_deg\n";
    for (int i = 0; i < rows; ++i)
      out << "view_" << std::to_string(100 + i).substr(1) << ".png," << pan(i) << "," << tilt(i)
          << "\n";
    return path.string();
  }

  // Exit 2, one line on stderr containing `what`, no output folder.
  void ExpectBadInput(const CommandRun& run, const std::string& what) const {
    EXPECT_EQ(run.code, 2) << run.err;
    EXPECT_NE(run.err.find(what), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_FALSE(fs::exists(dir_ / "out"));
  }

  static MountScene scene_;
  static fs::path shared_;
};

MountScene CalibrateMountCli::scene_;
fs::path CalibrateMountCli::shared_;

TEST_F(CalibrateMountCli, FromFilesWritesTheMountTheFloorAndThePictures) {
  const fs::path& shared = Rendered();
  const CommandRun run = Linetrack(
      "calibrate-mount" + FileFlags(shared, (shared / "angles.csv").string()) + " --floor-board " +
      (shared / "floor.png").string() + " --out " + (dir_ / "out").string());
  ASSERT_EQ(run.code, 0) << run.err << run.out;
  for (const char* file : {"mount.json", "eMc.yaml", "residuals.png"})
    EXPECT_TRUE(fs::exists(dir_ / "out" / file)) << file;
  EXPECT_FALSE(cv::imread((dir_ / "out" / "residuals.png").string()).empty());
  const nlohmann::json mount = ReadJson(dir_ / "out" / "mount.json");
  const Eigen::Matrix<double, 6, 1> error =
      PoseDelta(MatrixOf(mount["tilt_from_camera"]), scene_.tilt_from_camera);
  EXPECT_LT(error.head<3>().norm(), kMountPositionTolM);
  EXPECT_LT(RadToDeg(error.tail<3>().norm()), kMountRotationTolDeg);
  EXPECT_EQ(mount["views_used"].size(), 20u);
  EXPECT_EQ(mount["covariance"]["matrix"].size(), 36u);
  EXPECT_NEAR(mount["floor"]["crossing_height_m"].get<double>(), scene_.crossing_height,
              kFloorHeightTolM);
  EXPECT_NE(run.out.find("floor: crossing"), std::string::npos) << run.out;
}

TEST_F(CalibrateMountCli, AnImageMissingFromTheAnglesIsBadInput) {
  const std::string angles = Angles(
      "angles.csv", [](int i) { return -18.0 + 2.0 * i; }, [](int i) { return i % 3; }, 19);
  const fs::path blank = Blank(20);
  ExpectBadInput(
      Linetrack("calibrate-mount" + FileFlags(blank, angles) + " --out " + (dir_ / "out").string()),
      "view_19.png");
}

TEST_F(CalibrateMountCli, OneHeadAngleIsBadInput) {
  const std::string angles = Angles(
      "angles.csv", [](int) { return 5.0; }, [](int) { return 2.0; }, 20);
  const fs::path blank = Blank(20);
  ExpectBadInput(
      Linetrack("calibrate-mount" + FileFlags(blank, angles) + " --out " + (dir_ / "out").string()),
      "one head angle");
}

TEST_F(CalibrateMountCli, TurnsAboutOneAxisAreBadInput) {
  const std::string pan_only = Angles(
      "pan.csv", [](int i) { return -18.0 + 2.0 * i; }, [](int) { return 3.0; }, 20);
  const fs::path blank = Blank(20);
  ExpectBadInput(Linetrack("calibrate-mount" + FileFlags(blank, pan_only) + " --out " +
                           (dir_ / "out").string()),
                 "one axis only");
  const std::string tilt_only = Angles(
      "tilt.csv", [](int) { return 4.0; }, [](int i) { return -10.0 + i; }, 20);
  ExpectBadInput(Linetrack("calibrate-mount" + FileFlags(blank, tilt_only) + " --out " +
                           (dir_ / "out").string()),
                 "one axis only");
}

TEST_F(CalibrateMountCli, NoBoardFoundIsBadInput) {
  // Views at a good spread of angles that show no board.
  const std::string angles = Angles(
      "angles.csv", [](int i) { return -18.0 + 9.0 * (i % 5); },
      [](int i) { return -10.0 + 5.0 * (i / 5); }, 10);
  ExpectBadInput(Linetrack("calibrate-mount" + FileFlags(Blank(10), angles) + " --out " +
                           (dir_ / "out").string()),
                 "found in none");
}

TEST_F(CalibrateMountCli, LiveOnTheSimulatorWithItsBracketOffThenLiveUsesTheMount) {
  const std::string sim = " --source sim:bracket_mm=3:-4:2,bracket_deg=0.8:-1.2:0.5 --head sim";
  const std::string camera = " --camera " + kSource + "/tests/data/camera_wide.xml";
  const CommandRun run = Linetrack("calibrate-mount" + sim + camera + kBoardFlags +
                                   " --views 20 --out " + (dir_ / "mount").string());
  ASSERT_EQ(run.code, 0) << run.err << run.out;
  EXPECT_TRUE(fs::exists(dir_ / "mount" / "angles.csv"));
  EXPECT_TRUE(fs::exists(dir_ / "mount" / "views" / "view_20.png"));
  Eigen::Matrix<double, 6, 1> bracket;
  bracket << 0.003, -0.004, 0.002, DegToRad(0.8), DegToRad(-1.2), DegToRad(0.5);
  const Eigen::Isometry3d truth = MovedPose(test_support::NominalPtuMount(), bracket);
  const nlohmann::json mount = ReadJson(dir_ / "mount" / "mount.json");
  const Eigen::Matrix<double, 6, 1> error = PoseDelta(MatrixOf(mount["tilt_from_camera"]), truth);
  EXPECT_LT(error.head<3>().norm(), kSimPositionTolM) << run.out;
  EXPECT_LT(RadToDeg(error.tail<3>().norm()), kSimRotationTolDeg) << run.out;

  const CommandRun live = Linetrack(
      "live" + sim + camera + " --model " + kSource + "/models/hall.cao --prior 3,1.5,20 " +
      "--height 1.3 --target 9.25,2.75,1.5 --estimator truth --duration 1 --snapshot-every 0 " +
      "--mount " + (dir_ / "mount" / "mount.json").string() + " --out " + (dir_ / "live").string());
  ASSERT_EQ(live.code, 0) << live.err;
  const nlohmann::json summary = ReadJson(dir_ / "live" / "summary.json");
  EXPECT_NE(summary["mount"].get<std::string>().find("calibrated mount"), std::string::npos);
}

// `bench mount`: one seeded run of the live mode on the simulator, judged against its truth by the
// bench itself; a bad count of runs is refused.
TEST_F(CalibrateMountCli, BenchMountReportsTheErrorsOfASeededRun) {
  const std::string camera = " --camera " + kSource + "/tests/data/camera_wide.xml";
  ExpectBadInput(Linetrack("bench mount" + camera + " --seeds 0"), "--seeds");
  const CommandRun run = Linetrack("-q bench mount" + camera + " --seeds 1 --first-seed 3 --json");
  ASSERT_EQ(run.code, 0) << run.err << run.out;
  const nlohmann::json runs = nlohmann::json::parse(run.out);
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0]["seed"].get<int>(), 3);
  EXPECT_TRUE(runs[0]["ok"].get<bool>());
  EXPECT_GT(runs[0]["bracket_mm"].get<double>(), 0.0);
  EXPECT_LT(runs[0]["position_error_mm"].get<double>(), 1e3 * kSimPositionTolM);
  EXPECT_LT(runs[0]["rotation_error_deg"].get<double>(), kSimRotationTolDeg);
  EXPECT_GT(runs[0]["nees"].get<double>(), 0.0);
}

}  // namespace
}  // namespace linetrack
