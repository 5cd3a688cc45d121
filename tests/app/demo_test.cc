// The README's main job (scripts/demo.sh) runs its steps through scripts/demo_steps.sh; this
// test runs the same script with --quick (10 scenes, a 30-frame drive) against the built
// binary and judges every step's output against its ground truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "models/geometry.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kQuickScenes = 10;          // scripts/demo_steps.sh --quick
constexpr int kQuickFrames = 30;          // scripts/demo_steps.sh --quick
constexpr double kLocalizedShare = 0.8;   // QI3 scenes localised (docs/matching.md: ~97 %)
constexpr double kScenePositionM = 0.5;   // a localised scene's pose against its truth
constexpr double kSceneHeadingDeg = 5.0;  // (the benchmark's tolerance)
constexpr double kTrackedShare = 0.8;     // drive frames with a pose (the full demo: 119/120)
constexpr double kDriveAteM = 0.02;       // the full demo: 0.33 cm
constexpr double kDriveWorstDeg = 1.0;    // the full demo: 0.15 deg

std::map<std::string, json> ReadJsonLinesById(const fs::path& path) {
  std::map<std::string, json> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    const json j = json::parse(line);
    out[j["id"].get<std::string>()] = j;
  }
  return out;
}

json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  return json::parse(in);
}

class DemoSteps : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    out_ = fs::path(LINETRACK_BINARY_DIR) / "tests" / "demo_quick";
    fs::remove_all(out_);
    const std::string command = std::string("'") + LINETRACK_SOURCE_DIR +
                                "/scripts/demo_steps.sh' '" + LINETRACK_EXE + "' '" +
                                out_.string() + "' --quick > '" + out_.string() + ".log' 2>&1";
    status_ = std::system(command.c_str());
  }
  static fs::path out_;
  static int status_;
};
fs::path DemoSteps::out_;
int DemoSteps::status_ = -1;

TEST_F(DemoSteps, EveryStepSucceeds) {
  EXPECT_EQ(status_, 0) << "see " << out_.string() << ".log";
  EXPECT_TRUE(fs::is_regular_file(out_ / "table.md"));
  EXPECT_TRUE(fs::is_regular_file(out_ / "view_lines.csv"));
  EXPECT_TRUE(fs::is_regular_file(out_ / "localize_image.png"));  // written only for a pose
}

TEST_F(DemoSteps, SyntheticScenesLocaliseAtTheirTruth) {
  ASSERT_EQ(status_, 0);
  const auto truth = ReadJsonLinesById(out_ / "qi3" / "truth.jsonl");
  const auto results = ReadJsonLinesById(out_ / "qi3" / "results.jsonl");
  ASSERT_EQ(static_cast<int>(truth.size()), kQuickScenes);
  ASSERT_EQ(results.size(), truth.size());
  int localised = 0;
  for (const auto& [id, result] : results) {
    if (!result["found"].get<bool>()) continue;
    ++localised;
    const json& t = truth.at(id)["pose"];
    const json& p = result["pose"];
    const double position = std::hypot(p["x"].get<double>() - t["x"].get<double>(),
                                       p["y"].get<double>() - t["y"].get<double>());
    const double heading = linetrack::RadToDeg(std::abs(linetrack::WrapAngle(
        linetrack::DegToRad(p["heading_deg"].get<double>() - t["heading_deg"].get<double>()))));
    EXPECT_LE(position, kScenePositionM) << id;
    EXPECT_LE(heading, kSceneHeadingDeg) << id;
  }
  EXPECT_GE(localised, kLocalizedShare * kQuickScenes);
}

TEST_F(DemoSteps, DriveReplaysWithinTolerance) {
  ASSERT_EQ(status_, 0);
  const json summary = ReadJson(out_ / "replay" / "summary.json");
  EXPECT_EQ(summary["frames"].get<int>(), kQuickFrames);
  EXPECT_GE(summary["tracked"].get<int>(), kTrackedShare * kQuickFrames);
  ASSERT_TRUE(summary.contains("ground_truth"));
  EXPECT_LE(summary["ground_truth"]["ate_rmse_m"].get<double>(), kDriveAteM);
  EXPECT_LE(summary["ground_truth"]["rotation_deg"]["max"].get<double>(), kDriveWorstDeg);
  EXPECT_EQ(summary["integrity"]["ground_truth"]["integrity_failures"].get<int>(), 0);
}

}  // namespace
