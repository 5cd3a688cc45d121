// `linetrack replay` end to end: Castle-simu started from its first pose file with the ground
// truth as a pattern of pose files, a rendered hall sequence started by the matcher from its prior
// file, a source that breaks in the middle (files valid up to the last frame, summary saying so),
// and bad input, flags that cannot apply among it (exit 2, one line, no output folder).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/support/cli_test.h"

namespace linetrack {
namespace {

namespace fs = std::filesystem;
using test_support::CommandRun;
using test_support::ReadAll;

const std::string kSource = LINETRACK_SOURCE_DIR;
constexpr double kCastleMaxAteM = 0.005;
constexpr double kHallMaxAteM = 0.02;
constexpr int kMaxInitialisingFrames = 3;

int CountLines(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  int n = 0;
  while (std::getline(in, line))
    ++n;
  return n;
}

std::string VispImages() {
  const char* env = std::getenv("VISP_INPUT_IMAGE_PATH");
  return std::string(env ? env : "/usr/share/visp-images-data") + "/ViSP-images";
}

class ReplayCli : public test_support::CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    castle_ = VispImages() + "/mbt-depth/Castle-simu";
  }

  std::string CastleArgs(const std::string& input, const fs::path& out) const {
    return "replay --input '" + input + "' --model " + kSource +
           "/tests/data/visp/castle_simu_scene.cao --camera " + castle_ +
           "/Config/chateau.xml --settings " + castle_ + "/Config/chateau.xml --init-pose " +
           castle_ + "/CameraPose/Camera_001.txt --out " + out.string();
  }

  std::string castle_;
};

TEST_F(ReplayCli, CastleSimuFromItsPoseFileWithGroundTruth) {
  const fs::path out = dir_ / "castle";
  const CommandRun run = Linetrack(CastleArgs(castle_ + "/Images/Image_%04d.pgm", out) +
                                   " --ground-truth '" + castle_ + "/CameraPose/Camera_%03d.txt'");
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_EQ(CountLines(out / "poses.txt"), 1 + 40);  // header + every frame
  EXPECT_EQ(CountLines(out / "frames.csv"), 1 + 40);
  const nlohmann::json summary = nlohmann::json::parse(ReadAll(out / "summary.json"));
  EXPECT_TRUE(summary["complete"].get<bool>());
  EXPECT_EQ(summary["frames"].get<int>(), 40);
  EXPECT_DOUBLE_EQ(summary["tracked_share"].get<double>(), 1.0);
  EXPECT_EQ(summary["ground_truth"]["frames_compared"].get<int>(), 40);
  EXPECT_LT(summary["ground_truth"]["ate_rmse_m"].get<double>(), kCastleMaxAteM);
  EXPECT_GT(fs::file_size(out / "error_plot.png"), 1000u);
  const std::string overlay = summary["overlay"]["path"].get<std::string>();
  ASSERT_TRUE(fs::exists(overlay)) << overlay;
  EXPECT_GT(fs::file_size(overlay), 1000u);
  // frames.csv: the file numbers of the sequence (from 1), the status of each frame.
  std::ifstream csv(out / "frames.csv");
  std::string header, first;
  std::getline(csv, header);
  std::getline(csv, first);
  EXPECT_EQ(header.rfind("frame,time,status,projection_error_deg,moving_edges,time_ms", 0), 0u);
  EXPECT_EQ(first.rfind("1,0.000000,tracking,", 0), 0u) << first;
}

TEST_F(ReplayCli, RenderedHallStartedByTheMatcherFromItsPriorFile) {
  const fs::path seq = dir_ / "hall", out = dir_ / "replay";
  ASSERT_EQ(Linetrack("render --model " + kSource + "/models/hall.cao --camera " + kSource +
                      "/tests/data/camera_wide.xml --path hall-loop --nav " + kSource +
                      "/tests/data/hall.nav.json --frames 20 --clutter 5 --out " + seq.string())
                .code,
            0);
  const CommandRun run =
      Linetrack("replay --input '" + (seq / "frame_%05d.png").string() + "' --model " + kSource +
                "/models/hall.cao --camera " + (seq / "camera.xml").string() + " --prior-file " +
                (seq / "priors.csv").string() + " --ground-truth " +
                (seq / "groundtruth.txt").string() + " --overlay-png --out " + out.string());
  ASSERT_EQ(run.code, 0) << run.err;
  const nlohmann::json summary = nlohmann::json::parse(ReadAll(out / "summary.json"));
  // The first view (close to a wall) may not hold enough lines for the matcher: it starts within
  // the first frames, and from then on every frame has a pose.
  const nlohmann::json& counts = summary["status_counts"];
  EXPECT_LE(counts["initialising"].get<int>(), kMaxInitialisingFrames);
  EXPECT_EQ(counts["lost"].get<int>(), 0);
  EXPECT_EQ(summary["tracked"].get<int>(), 20 - counts["initialising"].get<int>());
  // The frame rate comes from the prior file (10 fps): every pose meets its ground truth.
  EXPECT_EQ(summary["ground_truth"]["frames_compared"].get<int>(), summary["tracked"].get<int>());
  EXPECT_LT(summary["ground_truth"]["ate_rmse_m"].get<double>(), kHallMaxAteM);
  EXPECT_TRUE(fs::exists(out / "overlay" / "frame_00000.png"));
  EXPECT_TRUE(fs::exists(out / "overlay" / "frame_00019.png"));
}

TEST_F(ReplayCli, ABrokenSourceLeavesValidFilesAndSaysSo) {
  // Castle frames 1-8 as a sequence whose 6th file is not an image.
  const fs::path seq = dir_ / "seq";
  fs::create_directories(seq);
  for (int i = 1; i <= 8; ++i) {
    char name[32], from[32];
    std::snprintf(name, sizeof(name), "img_%02d.pgm", i);
    std::snprintf(from, sizeof(from), "/Images/Image_%04d.pgm", i);
    if (i == 6) {
      std::ofstream(seq / name) << "not an image";
    } else {
      fs::copy_file(castle_ + from, seq / name);
    }
  }
  const fs::path out = dir_ / "out";
  const CommandRun run =
      Linetrack(CastleArgs((seq / "img_%02d.pgm").string(), out) + " --no-overlay");
  EXPECT_EQ(run.code, 1) << run.err;
  const nlohmann::json summary = nlohmann::json::parse(ReadAll(out / "summary.json"));
  EXPECT_FALSE(summary["complete"].get<bool>());
  EXPECT_TRUE(summary["interrupted"].get<bool>());
  EXPECT_NE(summary["interruption"].get<std::string>().find("source"), std::string::npos);
  EXPECT_EQ(summary["frames"].get<int>(), 5);
  EXPECT_EQ(CountLines(out / "frames.csv"), 1 + 5);
  EXPECT_EQ(CountLines(out / "poses.txt"), 1 + 5);
}

TEST_F(ReplayCli, BadInputExitsTwoWithOneLineAndWritesNothing) {
  const fs::path out = dir_ / "never";
  const std::string castle_input = castle_ + "/Images/Image_%04d.pgm";
  const std::vector<std::string> bad = {
      CastleArgs(dir_.string() + "/missing_%04d.png", out),
      CastleArgs(castle_input, out) + " --settings " + kSource + "/models/hall.cao",
      CastleArgs(castle_input, out) + " --prior 1,2,30",
      CastleArgs(castle_input, out) + " --ground-truth " + dir_.string() + "/none.txt",
      "replay --input '" + castle_input + "' --model " + kSource + "/models/hall.cao --camera " +
          castle_ + "/Config/chateau.xml --out " + out.string(),  // nothing to start from
      CastleArgs(castle_input, out) + " --init-pose " + kSource + "/models/hall.cao",
  };
  for (const std::string& args : bad) {
    const CommandRun run = Linetrack(args);
    EXPECT_EQ(run.code, 2) << args << "\n" << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_FALSE(fs::exists(out)) << args;
  }
}

TEST_F(ReplayCli, HeightAndInapplicableFlagsAreBadInput) {
  const fs::path out = dir_ / "never";
  const std::string castle = CastleArgs(castle_ + "/Images/Image_%04d.pgm", out);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {castle + " --prior 1,2,30 --height -1 --tilt 0", "--height"},
      {castle + " --prior 1,2,30 --height 0 --tilt 0", "--height"},
      {castle + " --prior 1,2,30 --height nan --tilt 0", "--height"},
      {castle + " --overlay-png --no-overlay", "--overlay-png"},
      {castle + " --delta-t 1", "--delta-t"},      // no robot: no matcher to bound
      {castle + " --detector lsd", "--detector"},  // nor to extract lines for
      {castle + " --prior-file p.csv --tilt 3", "--tilt"},
  };
  for (const auto& [args, flag] : bad) {
    const CommandRun run = Linetrack(args);
    EXPECT_EQ(run.code, 2) << args << "\n" << run.err;
    EXPECT_NE(run.err.find(flag), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_FALSE(fs::exists(out)) << args;
  }
}

TEST_F(ReplayCli, QuietAfterTheSubcommand) {
  const fs::path out = dir_ / "quiet";
  const CommandRun run = Linetrack(CastleArgs(castle_ + "/Images/Image_%04d.pgm", out) +
                                   " --frames 3 --no-overlay -q");
  EXPECT_EQ(run.code, 0) << run.err;
  EXPECT_TRUE(run.err.empty()) << run.err;
  EXPECT_NE(run.out.find("replayed 3 frames"), std::string::npos) << run.out;
}

TEST_F(ReplayCli, HelpNamesTheOptions) {
  const CommandRun run = Linetrack("replay --help");
  EXPECT_EQ(run.code, 0);
  for (const char* flag : {"--input", "--prior-file", "--init-pose", "--ground-truth",
                           "--overlay-png", "--settings"}) {
    EXPECT_NE(run.out.find(flag), std::string::npos) << flag;
  }
}

}  // namespace
}  // namespace linetrack
