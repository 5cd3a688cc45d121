// What a new user meets across the commands: global flags after the subcommand, flags that
// cannot apply refused with one line (never silently ignored), `model-info --edges` naming every
// edge, and `bench match` keeping its developer's table behind --verbose.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/support/cli_test.h"

namespace linetrack {
namespace {

const std::string kSource = LINETRACK_SOURCE_DIR;
const std::string kHall = kSource + "/models/hall.cao";

class UsageCli : public test_support::CliTest {};
using test_support::CommandRun;

// The file's text, or "(none)" when it is not there; removes it.
std::string TakeFile(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) return "(none)";
  const std::string text = test_support::ReadAll(path);
  std::filesystem::remove(path);
  return text;
}

// `text` without its lines that report a time in milliseconds ("..._ms").
std::string WithoutTimings(const std::string& text) {
  std::istringstream lines(text);
  std::string line, kept;
  while (std::getline(lines, line)) {
    if (line.find("_ms\"") == std::string::npos) kept += line + "\n";
  }
  return kept;
}

TEST_F(UsageCli, FlagsThatCannotApplyAreRefused) {
  const std::string out = (dir_ / "never").string();
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"calibrate --images a.png --frames 5 --out " + out, "--frames"},
      {"calibrate --images a.png --pattern chessboard --marker 0.02 --out " + out, "--marker"},
      {"calibrate --images a.png --pattern circles --sb --out " + out, "--sb"},
      {"calibrate --images a.png --keep-all --outlier-factor 2 --out " + out, "--outlier-factor"},
      {"bench calibrate --images a.png --pattern circles --dictionary DICT_4X4_50", "--dictionary"},
      {"model-info " + kHall + " --query-radius 1", "--query-radius"},
      {"synth --model " + kHall + " --out " + out + " --exact --angle-sigma 2", "--angle-sigma"},
      {"bench match --model " + kHall + " --no-baseline --baseline-samples 10",
       "--baseline-samples"},
      {"bench servo --model " + kHall + " --camera c.xml --estimator truth --settings s.xml",
       "--settings"},
      {"bench servo --model " + kHall + " --camera c.xml --jitter-deg 1", "--jitter-deg"},
      {"bench capture --source v4l2:/dev/video9 --pixel-format Mono16", "--pixel-format"},
      {"bench capture --source aravis:X --fake-serial Y", "--fake-serial"},
      {"render --model " + kHall + " --camera c.xml --trajectory t.txt --pan-amplitude 20 --out " +
           out,
       "--pan-amplitude"},
      {"render --model " + kHall + " --camera c.xml --trajectory t.txt --speed 2 --out " + out,
       "--speed"},
      {"render --model " + kHall + " --camera c.xml --pose 1,2,3 --frames 10 --out " + out + ".png",
       "--frames"},
      {"replay --input v.mp4 --model " + kHall + " --camera c.xml --init-pose p.pos " +
           "--image-topic /camera/image_raw --out " + out,
       "--image-topic"},
      {"replay --input v.mp4 --model " + kHall + " --camera c.xml --init-pose p.pos --out-bag " +
           out + ".bag --out " + out,
       "--out-bag"},
  };
  for (const auto& [args, flag] : refused) {
    const CommandRun run = Linetrack(args);
    EXPECT_EQ(run.code, 2) << args;
    EXPECT_NE(run.err.find(flag), std::string::npos) << args << ": " << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_TRUE(run.out.empty()) << run.out;
  }
  EXPECT_FALSE(std::filesystem::exists(dir_ / "never"));
}

TEST_F(UsageCli, GlobalFlagsWorkOnEitherSide) {
  // -q silences the info lines of the nested `bench` commands as well, on either side.
  const std::string bench =
      "bench match --model " + kHall + " --count 2 --series qi1 --no-baseline";
  const CommandRun loud = Linetrack(bench);
  const CommandRun before = Linetrack("-q " + bench);
  const CommandRun after = Linetrack(bench + " -q");
  ASSERT_EQ(loud.code, 0) << loud.err;
  EXPECT_NE(loud.err.find("info"), std::string::npos) << loud.err;
  EXPECT_EQ(before.code, 0) << before.err;
  EXPECT_EQ(after.code, 0) << after.err;
  EXPECT_TRUE(before.err.empty()) << before.err;
  EXPECT_TRUE(after.err.empty()) << after.err;
  EXPECT_EQ(Linetrack("model-info " + kHall + " --version").code, 0);
}

TEST_F(UsageCli, BenchMatchKeepsTheDevelopersTableBehindVerbose) {
  const std::string bench =
      "-q bench match --model " + kHall + " --count 3 --series qi1 --no-baseline";
  const CommandRun plain = Linetrack(bench);
  const CommandRun verbose = Linetrack(bench + " --verbose");
  ASSERT_EQ(plain.code, 0) << plain.err;
  ASSERT_EQ(verbose.code, 0) << verbose.err;
  const std::string kTable = "Posterior of the doubted unreported groups";
  EXPECT_EQ(plain.out.find(kTable), std::string::npos) << plain.out;
  EXPECT_NE(verbose.out.find(kTable), std::string::npos) << verbose.out;
  EXPECT_NE(plain.out.find("| QI1 (0.30 m, 10 deg) | tree |"), std::string::npos) << plain.out;
}

TEST_F(UsageCli, ModelInfoListsEveryEdgeWithItsName) {
  const CommandRun json = Linetrack("model-info " + kHall + " --edges --json");
  ASSERT_EQ(json.code, 0) << json.err;
  const nlohmann::json info = nlohmann::json::parse(json.out);
  const nlohmann::json& edges = info["edge_list"];
  ASSERT_EQ(edges.size(), info["edges"].get<size_t>());
  for (size_t i = 0; i < edges.size(); ++i) {
    EXPECT_EQ(edges[i]["id"].get<size_t>(), i);
    EXPECT_FALSE(edges[i]["name"].get<std::string>().empty()) << edges[i].dump();
    EXPECT_EQ(edges[i]["from"].size(), 3u);
  }
  // The hall's first 3D line and the corner where its south and east walls meet.
  EXPECT_EQ(edges[0]["name"], "door_south_jamb_a");
  EXPECT_EQ(edges[0]["from"], nlohmann::json({2.0, 0.0, 0.0}));
  EXPECT_EQ(edges[0]["to"], nlohmann::json({2.0, 0.0, 2.1}));
  const auto corner = std::find_if(edges.begin(), edges.end(), [](const nlohmann::json& e) {
    return e["name"] == "wall_south/wall_east";
  });
  ASSERT_NE(corner, edges.end());
  EXPECT_TRUE((*corner)["vertical"].get<bool>());

  const CommandRun text = Linetrack("model-info " + kHall + " --edges");
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("   0  door_south_jamb_a"), std::string::npos) << text.out;
}

// The CLI server (tests/support/cli_server.cc) runs the binary's own code: the same exit codes,
// stdout (but its timings), stderr and files as the binary, quoted words included.
TEST_F(UsageCli, TheCliServerRunsWhatTheBinaryRuns) {
  const std::filesystem::path written = dir_ / "with space.cao";
  const std::vector<std::string> commands = {
      "--version",
      "model-info " + kHall + " --json",
      "model-info " + kSource + "/models/missing.cao",
      "localize --lines nothing.csv --model " + kHall,
      "make-building '" + written.string() + "'",
      "no-such-command",
  };
  for (const std::string& args : commands) {
    const CommandRun server = Linetrack(args);
    const std::string server_file = TakeFile(written);
    const CommandRun binary = LinetrackBinary(args);
    EXPECT_EQ(server.code, binary.code) << args;
    EXPECT_EQ(WithoutTimings(server.out), WithoutTimings(binary.out)) << args;
    EXPECT_EQ(server.err, binary.err) << args;
    EXPECT_EQ(server_file, TakeFile(written)) << args;
  }
}

}  // namespace
}  // namespace linetrack
