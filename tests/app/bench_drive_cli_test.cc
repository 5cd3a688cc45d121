// `linetrack bench drive` on a 20-frame drive: the table and the worst frames, the rendered drive
// kept in the work folder and reused, bad drive files refused with one line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tests/support/cli_test.h"

namespace linetrack {
namespace {

namespace fs = std::filesystem;

const std::string kSource = LINETRACK_SOURCE_DIR;
const std::string kTiny = kSource + "/tests/data/drives/tiny_hall.json";

class BenchDriveCli : public test_support::CliTest {};

TEST_F(BenchDriveCli, ATinyDriveGivesTheTable) {
  const fs::path work = dir_ / "work";
  const std::string args = "bench drive " + kTiny + " --work " + work.string() + " --frames 20";
  const test_support::CommandRun run = Linetrack(args);
  ASSERT_EQ(run.code, 0) << run.err;
  for (const char* row :
       {"| | tiny-hall |", "| frames (observable) | 20 (",
        "| availability: observable frames with a pose |",
        "| frames to recover after each blackout |", "| ATE (camera centre RMSE) |",
        "| integrity failures (`tracking` beyond its protection level) | 0 |",
        "| NEES (x, y, heading) within chi2(3) 50 / 90 / 99 / 99.9 %; mean (3) |",
        "| `tracking` poses beyond 10 cm / 2 deg | 0 |", "### tiny-hall: worst frames"}) {
    EXPECT_NE(run.out.find(row), std::string::npos) << row << "\n" << run.out;
  }
  EXPECT_TRUE(fs::exists(work / "tiny-hall" / "frames" / "frame_00019.png"));
  EXPECT_FALSE(fs::exists(work / "tiny-hall" / "frames" / "frame_00020.png"));
  EXPECT_TRUE(fs::exists(work / "tiny-hall" / "replay" / "frames.csv"));
  EXPECT_EQ(run.out.find("replayed"), std::string::npos);  // replay's own line stays out

  const test_support::CommandRun again = Linetrack(args);
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_NE(again.err.find("rendered frames found"), std::string::npos) << again.err;
  EXPECT_EQ(again.out.substr(0, again.out.find("| replay fps")),
            run.out.substr(0, run.out.find("| replay fps")));
}

TEST_F(BenchDriveCli, BadDriveFilesExitTwo) {
  const std::string unknown = (dir_ / "unknown.json").string();
  std::ofstream(unknown) << R"({"name": "x", "render": {"model": "m.cao", "camera": "c.xml",
                                "wings": 2}})";
  const std::string broken = (dir_ / "broken.json").string();
  std::ofstream(broken) << "{\"name\": ";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"/nonexistent/drive.json", "/nonexistent/drive.json"},
      {unknown, "unknown.json: "},
      {broken, "broken.json: not a drive file"},
  };
  for (const auto& [file, what] : cases) {
    const test_support::CommandRun run =
        Linetrack("bench drive " + file + " --work " + (dir_ / "w").string());
    EXPECT_EQ(run.code, 2) << file;
    EXPECT_NE(run.err.find(what), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  }
}

}  // namespace
}  // namespace linetrack
