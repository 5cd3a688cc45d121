// `linetrack synth` end to end: the cases parse back through the batch reader of `localize`,
// the truth agrees with them, the seed decides the files, `localize --batch` runs on them, and
// bad input exits 2 with one line and writes nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "app/localize_io.h"
#include "models/camera.h"
#include "models/robot_pose.h"
#include "tests/support/cli_test.h"

namespace linetrack {
namespace {

namespace fs = std::filesystem;
using test_support::CommandRun;
using test_support::ReadAll;

constexpr double kCmoTol = 1e-9;
constexpr double kBoundSlack = 1e-9;

const std::string kSource = LINETRACK_SOURCE_DIR;
const std::string kModel = kSource + "/models/hall.cao";

std::vector<nlohmann::json> ReadJsonLines(const std::string& path) {
  std::vector<nlohmann::json> rows;
  std::ifstream in(path);
  std::string row;
  while (std::getline(in, row))
    rows.push_back(nlohmann::json::parse(row));
  return rows;
}

class SynthCli : public test_support::CliTest {};

TEST_F(SynthCli, CasesParseAsABatchAndAgreeWithTheTruth) {
  const fs::path out = dir_ / "qi2";
  const CommandRun run =
      Linetrack("synth --model " + kModel + " --out " + out.string() + " --count 12 --qi 2");
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find("wrote 12 cases"), std::string::npos) << run.out;
  const std::vector<nlohmann::json> cases = ReadJsonLines((out / "cases.jsonl").string());
  const std::vector<nlohmann::json> truth = ReadJsonLines((out / "truth.jsonl").string());
  ASSERT_EQ(cases.size(), 12u);
  ASSERT_EQ(truth.size(), 12u);
  const CameraIntrinsics camera = ReadCameraXml((out / "camera.xml").string());
  EXPECT_EQ(camera.width, 640);
  EXPECT_EQ(camera.height, 480);
  EXPECT_DOUBLE_EQ(camera.px, 1000.0);
  EXPECT_DOUBLE_EQ(camera.u0, 320.0);
  for (size_t i = 0; i < cases.size(); ++i) {
    const app::BatchCase c = app::ParseBatchCase(cases[i], out.string());
    char id[32];
    std::snprintf(id, sizeof(id), "hall-qi2-%05zu", i);
    EXPECT_EQ(c.id, std::string(id));
    EXPECT_TRUE(fs::equivalent(c.model_path, kModel)) << c.model_path;
    EXPECT_TRUE(fs::equivalent(c.camera_path, out / "camera.xml")) << c.camera_path;
    EXPECT_NEAR(c.problem.delta_t, 0.5, 1e-12);
    EXPECT_NEAR(RadToDeg(c.problem.delta_phi), 15.0, 1e-9);
    const nlohmann::json& t = truth[i];
    ASSERT_EQ(t["id"], cases[i]["id"]);
    const nlohmann::json& p = t["pose"];
    const RobotPose pose{p["x"].get<double>(), p["y"].get<double>(),
                         DegToRad(p["heading_deg"].get<double>()), p["height"].get<double>(),
                         DegToRad(p["tilt_deg"].get<double>())};
    EXPECT_NEAR(c.problem.height, pose.height, 1e-12);
    EXPECT_NEAR(c.problem.tilt, pose.tilt, 1e-12);
    EXPECT_LE(std::hypot(c.problem.prior.x - pose.x, c.problem.prior.y - pose.y),
              c.problem.delta_t + kBoundSlack);
    EXPECT_LE(std::abs(WrapAngle(c.problem.prior.heading - pose.heading)),
              c.problem.delta_phi + kBoundSlack);
    const Eigen::Matrix4d expected = CamFromWorld(pose).matrix();
    for (int r = 0; r < 4; ++r) {
      for (int k = 0; k < 4; ++k)
        EXPECT_NEAR(t["cMo"][r][k].get<double>(), expected(r, k), kCmoTol);
    }
    // Matches and clutter partition the lines.
    std::multiset<int> seen;
    for (const auto& m : t["matches"])
      seen.insert(m[1].get<int>());
    for (const auto& k : t["clutter"])
      seen.insert(k.get<int>());
    ASSERT_EQ(seen.size(), c.problem.lines.size());
    for (int k = 0; k < static_cast<int>(c.problem.lines.size()); ++k)
      EXPECT_EQ(seen.count(k), 1u);
    EXPECT_GT(t["calibration_scale"].get<double>(), 0.8);
  }
}

TEST_F(SynthCli, SeedDecidesTheFilesAndLocalizeReadsThem) {
  auto synth = [&](const std::string& name, int seed) {
    const CommandRun run =
        Linetrack("synth --model " + kModel + " --out " + (dir_ / name).string() +
                  " --count 4 --seed " + std::to_string(seed));
    EXPECT_EQ(run.code, 0) << run.err;
    return ReadAll((dir_ / name / "cases.jsonl").string()) +
           ReadAll((dir_ / name / "truth.jsonl").string());
  };
  const std::string first = synth("a", 5);
  EXPECT_EQ(first, synth("b", 5));  // same depth below dir_: same relative model path
  EXPECT_NE(first, synth("c", 6));

  const CommandRun run = Linetrack("localize --batch " + (dir_ / "a" / "cases.jsonl").string());
  ASSERT_EQ(run.code, 0) << run.err;
  std::istringstream rows(run.out);
  std::string row;
  int n = 0;
  for (; std::getline(rows, row); ++n) {
    const nlohmann::json result = nlohmann::json::parse(row);
    EXPECT_FALSE(result.contains("error")) << row;
    EXPECT_TRUE(result.contains("found")) << row;
    EXPECT_EQ(result["id"], "hall-qi1-0000" + std::to_string(n));
  }
  EXPECT_EQ(n, 4);
}

TEST_F(SynthCli, ExactScenesHaveNoCalibrationError) {
  const fs::path out = dir_ / "exact";
  ASSERT_EQ(Linetrack("synth --exact --count 3 --model " + kModel + " --out " + out.string()).code,
            0);
  for (const nlohmann::json& t : ReadJsonLines((out / "truth.jsonl").string())) {
    EXPECT_EQ(t["calibration_scale"].get<double>(), 1.0);
  }
}

TEST_F(SynthCli, BadInputExitsTwoWithOneLineAndWritesNothing) {
  const std::string out = (dir_ / "out").string();
  const std::string model = " --model " + kModel + " --out " + out;
  const std::string bad_cao = kSource + "/tests/data/cao_malformed/bad_point_count.cao";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--model /nonexistent.cao --out " + out, "/nonexistent.cao"},
      {"--model " + bad_cao + " --out " + out, "bad_point_count.cao"},
      {"--out " + out, "--model"},
      {model + " --count 0", "--count"},
      {model + " --count -3", "--count"},
      {model + " --count many", "--count"},
      {model + " --height-range 1.5,1.2", "--height-range"},
      {model + " --height-range nan,1.2", "--height-range"},
      {model + " --tilt-range 0,95", "--tilt-range"},
      {model + " --qi 4", "--qi"},
      {model + " --qi 2 --delta-t 0.3 --delta-phi 10", "exclusive"},
      {model + " --delta-t 0.3", "together"},
      {model + " --delta-t 0.3 --delta-phi nan", "--delta-phi"},
      {model + " --delta-t -1 --delta-phi 10", "--delta-t"},
      {model + " --offset-sigma -1", "--offset-sigma"},
      {model + " --camera /nonexistent.xml", "/nonexistent.xml"},
  };
  for (const auto& [args, what] : cases) {
    const CommandRun run = Linetrack("synth " + args);
    EXPECT_EQ(run.code, 2) << args;
    EXPECT_NE(run.err.find(what), std::string::npos) << args << " -> " << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_TRUE(run.out.empty()) << run.out;
    EXPECT_FALSE(fs::exists(out)) << args;
  }
}

}  // namespace
}  // namespace linetrack
