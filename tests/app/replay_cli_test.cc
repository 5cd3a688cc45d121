// `linetrack replay` end to end: Castle-simu started from its first pose file with the ground
// truth as a pattern of pose files, a rendered hall sequence started by the matcher from its prior
// file, a source that breaks in the middle (files valid up to the last frame, summary saying so),
// and bad input, flags that cannot apply among it (exit 2, one line, no output folder).
#include <gtest/gtest.h>

#include <algorithm>
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
// The castle is a tabletop model, exact in the simulation: its edges are where the model says
// to half a millimetre (the default model-error allowance, 3 mm, is a building's).
const std::string kCastleModelSigma = "0.0005";
constexpr int kCastleMinTracking = 36;  // of 40
constexpr double kHallMaxAteM = 0.02;
constexpr int kMaxInitialisingFrames = 3;
constexpr double kEpochS = 1.7e9;  // a time base in epoch seconds

int CountLines(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  int n = 0;
  while (std::getline(in, line))
    ++n;
  return n;
}

// Copies a prior file (CSV) or TUM file with `offset` seconds added to its first field.
void ShiftTimes(const fs::path& from, double offset, char separator, const fs::path& to) {
  std::ifstream in(from);
  std::ofstream out(to);
  std::string line;
  while (std::getline(in, line)) {
    const size_t end = line.find(separator);
    if (line.empty() || line[0] == '#' || end == std::string::npos ||
        line.find_first_not_of("0123456789.-") < end) {
      out << line << "\n";  // header or comment
      continue;
    }
    std::ostringstream shifted;
    shifted.precision(15);
    shifted << std::stod(line.substr(0, end)) + offset << line.substr(end) << "\n";
    out << shifted.str();
  }
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
           castle_ + "/CameraPose/Camera_001.txt --model-sigma " + kCastleModelSigma + " --out " +
           out.string();
  }

  std::string castle_;
};

TEST_F(ReplayCli, CastleSimuFromItsPoseFileWithGroundTruth) {
  const fs::path out = dir_ / "castle";
  const CommandRun run = Linetrack(CastleArgs(castle_ + "/Images/Image_%04d.pgm", out) +
                                   " --ground-truth '" + castle_ + "/CameraPose/Camera_%03d.txt'");
  ASSERT_EQ(run.code, 0) << run.err;
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
  // Issue 14: poses.txt holds the poses `tracking` (nearly all), none beyond its protection level.
  const nlohmann::json& integrity = summary["integrity"];
  const int tracking = integrity["status_counts"]["tracking"].get<int>();
  EXPECT_GE(tracking, kCastleMinTracking);
  EXPECT_EQ(CountLines(out / "poses.txt"), 1 + tracking);
  EXPECT_EQ(integrity["ground_truth"]["integrity_failures"].get<int>(), 0);
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
  // Issue 14: the integrity of every pose. No pose `tracking` is beyond its protection levels;
  // poses.txt holds the `tracking` poses; covariance.jsonl a line per frame.
  const nlohmann::json& integrity = summary["integrity"];
  EXPECT_EQ(integrity["ground_truth"]["integrity_failures"].get<int>(), 0);
  EXPECT_GT(integrity["status_counts"]["tracking"].get<int>(), 0);
  EXPECT_EQ(CountLines(out / "poses.txt"), 1 + integrity["status_counts"]["tracking"].get<int>());
  EXPECT_EQ(CountLines(out / "covariance.jsonl"), 20);
  EXPECT_GT(integrity["sigma_x_m"]["p50"].get<double>(), 0.0);
  std::ifstream csv(out / "frames.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find(",state,sigma_x_m,sigma_y_m,sigma_heading_deg,protection_level_m,"
                        "protection_level_deg,"),
            std::string::npos)
      << header;

  // Time bases: the prior file and the ground truth stamped in epoch seconds against frames
  // timed from 0 are refused in one line (exit 2, no output); --align-times reads them.
  const fs::path epoch_priors = dir_ / "epoch_priors.csv", epoch_truth = dir_ / "epoch_truth.txt";
  ShiftTimes(seq / "priors.csv", kEpochS, ',', epoch_priors);
  ShiftTimes(seq / "groundtruth.txt", kEpochS, ' ', epoch_truth);
  const std::string base = "replay --input '" + (seq / "frame_%05d.png").string() + "' --model " +
                           kSource + "/models/hall.cao --camera " + (seq / "camera.xml").string() +
                           " --no-overlay --frames 4 ";
  const fs::path never = dir_ / "never";
  for (const std::string& args :
       {base + "--prior-file " + epoch_priors.string() + " --out " + never.string(),
        base + "--prior-file " + (seq / "priors.csv").string() + " --ground-truth " +
            epoch_truth.string() + " --out " + never.string()}) {
    const CommandRun bad = Linetrack(args);
    EXPECT_EQ(bad.code, 2) << bad.err;
    EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
    EXPECT_NE(bad.err.find("do not overlap"), std::string::npos) << bad.err;
    EXPECT_FALSE(fs::exists(never));
  }
  const fs::path aligned = dir_ / "aligned";
  const CommandRun run_aligned = Linetrack(base + "--prior-file " + epoch_priors.string() +
                                           " --align-times --out " + aligned.string());
  EXPECT_EQ(run_aligned.code, 0) << run_aligned.err;
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
      {castle + " --kidnap-after-s -1", "--kidnap-after-s"},
      {castle + " --kidnap-after 3", "--kidnap-after-s"},  // the former frame count
      {castle + " --global-after 25", "--global-after-s"},
      {castle + " --global-after-s nan", "--global-after-s"},
      {castle + " --global-after-m nan", "--global-after-m"},
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
  for (const char* flag :
       {"--input", "--prior-file", "--init-pose", "--ground-truth", "--overlay-png", "--settings",
        "--kidnap-after-s", "--global-after-s", "--no-global"}) {
    EXPECT_NE(run.out.find(flag), std::string::npos) << flag;
  }
}

}  // namespace
}  // namespace linetrack
