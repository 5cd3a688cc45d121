// `linetrack heading`, `linetrack views` and `localize --global` end to end: the heading of a
// rendered hall view (tilt given and estimated) and of exact lines, a view database built on a
// grid of the room and read back, an image localised against it, the room localised with no
// prior (lines, batch, image through the integrity gate), and bad input (exit 2, one line).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "models/occlusion.h"
#include "models/robot_pose.h"
#include "models/wireframe.h"
#include "tests/support/cli_test.h"

namespace linetrack {
namespace {

using test_support::CommandRun;
using test_support::ReadAll;
namespace fs = std::filesystem;

const std::string kSource = LINETRACK_SOURCE_DIR;
const std::string kHall = kSource + "/models/hall.cao";
const std::string kRoom = kSource + "/models/room.cao";
const std::string kCamera = kSource + "/tests/data/camera_paper.xml";
const std::string kWideCamera = kSource + "/tests/data/camera_wide.xml";
constexpr double kHeadingTolDeg = 1.0;  // the target for one candidate
constexpr double kTiltTolDeg = 0.5;
constexpr double kPositionTolM = 0.3;  // a correct answer (the benchmarks' tolerance)
constexpr double kPoseHeadingTolDeg = 3.0;

// The global answer's pose is the truth's (x, y, heading_deg).
void ExpectPoseNear(const nlohmann::json& pose, double x, double y, double heading_deg) {
  EXPECT_NEAR(pose["x"].get<double>(), x, kPositionTolM) << pose;
  EXPECT_NEAR(pose["y"].get<double>(), y, kPositionTolM) << pose;
  EXPECT_LT(std::abs(std::remainder(pose["heading_deg"].get<double>() - heading_deg, 360.0)),
            kPoseHeadingTolDeg)
      << pose;
}

double NearestCandidateDeg(const nlohmann::json& headings, double truth_deg) {
  double best = 360.0;
  for (const auto& h : headings) {
    best = std::min(best, std::abs(std::remainder(h.get<double>() - truth_deg, 360.0)));
  }
  return best;
}

class HeadingViewsCli : public test_support::CliTest {
 protected:
  std::string Render(const std::string& model, const std::string& camera, const std::string& pose,
                     double tilt_deg) {
    const std::string out = (dir_ / "view.png").string();
    std::ostringstream args;
    args << "render --model " << model << " --camera " << camera << " --pose " << pose
         << " --height 1.3 --tilt " << tilt_deg << " --clutter 5 --out " << out;
    const CommandRun run = Linetrack(args.str());
    EXPECT_EQ(run.code, 0) << run.err;
    return out;
  }

  // The exact visible edge pieces (at least 20 px) seen from `pose`, as a lines CSV.
  std::string ExactLinesCsv(const std::string& model_path, const RobotPose& pose,
                            const std::string& name) {
    const WireframeModel model = WireframeModel::Load(model_path);
    const OcclusionTester occlusion(model);
    CameraIntrinsics camera = ReadCameraXml(kCamera);
    std::ostringstream csv;
    csv << "u1,v1,u2,v2\n" << std::setprecision(10);
    for (const ProjectedEdge& p :
         ProjectVisibleEdges(model, occlusion, CamFromWorld(pose), camera)) {
      if (p.image.Length() < 20.0) continue;
      csv << p.image.a.x() << "," << p.image.a.y() << "," << p.image.b.x() << "," << p.image.b.y()
          << "\n";
    }
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << csv.str();
    return path;
  }
};

TEST_F(HeadingViewsCli, HeadingOfARenderedViewWithTiltGivenAndEstimated) {
  const std::string image = Render(kHall, kWideCamera, "3.0,2.0,35", 6.0);
  const CommandRun given = Linetrack("heading " + image + " --camera " + kWideCamera + " --model " +
                                     kHall + " --tilt 6 --json");
  ASSERT_EQ(given.code, 0) << given.err;
  const nlohmann::json a = nlohmann::json::parse(given.out);
  EXPECT_TRUE(a["found"].get<bool>());
  EXPECT_EQ(a["headings_deg"].size(), 4u);  // the hall's quarter turns
  EXPECT_LT(NearestCandidateDeg(a["headings_deg"], 35.0), kHeadingTolDeg);
  EXPECT_EQ(a["tilt_deg"].get<double>(), 6.0);
  EXPECT_GT(a["vertical_lines"].get<int>(), 0);
  ASSERT_FALSE(a["vanishing_points"].empty());
  EXPECT_EQ(a["vanishing_points"][0]["direction"], "vertical");
  for (const auto& vp : a["vanishing_points"])
    EXPECT_FALSE(vp["lines"].empty());

  const CommandRun estimated =
      Linetrack("heading " + image + " --camera " + kWideCamera + " --model " + kHall + " --json");
  ASSERT_EQ(estimated.code, 0) << estimated.err;
  const nlohmann::json b = nlohmann::json::parse(estimated.out);
  EXPECT_TRUE(b["tilt_estimated"].get<bool>());
  EXPECT_NEAR(b["tilt_deg"].get<double>(), 6.0, kTiltTolDeg);
  EXPECT_LT(NearestCandidateDeg(b["headings_deg"], 35.0), kHeadingTolDeg);
}

TEST_F(HeadingViewsCli, HeadingOfExactLinesAndTheTextForm) {
  const std::string csv =
      ExactLinesCsv(kHall, {3.0, 2.0, DegToRad(35.0), 1.4, DegToRad(4.0)}, "l.csv");
  const CommandRun run = Linetrack("heading --lines " + csv + " --camera " + kCamera + " --model " +
                                   kHall + " --tilt 4");
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find("heading candidates (deg):"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("(given)"), std::string::npos);
}

TEST_F(HeadingViewsCli, HeadingBadInputExitsTwoWithOneLine) {
  const CommandRun missing = Linetrack("heading --lines " + (dir_ / "none.csv").string() +
                                       " --camera " + kCamera + " --model " + kHall);
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("none.csv"), std::string::npos) << missing.err;
  const CommandRun neither = Linetrack("heading --camera " + kCamera + " --model " + kHall);
  EXPECT_EQ(neither.code, 2);
  EXPECT_NE(neither.err.find("IMAGE or --lines"), std::string::npos) << neither.err;
  const std::string csv = ExactLinesCsv(kHall, {7.0, 3.0, 0.3, 1.4, 0.05}, "l.csv");
  const CommandRun tilt = Linetrack("heading --lines " + csv + " --camera " + kCamera +
                                    " --model " + kHall + " --tilt 95");
  EXPECT_EQ(tilt.code, 2);
  EXPECT_NE(tilt.err.find("--tilt"), std::string::npos) << tilt.err;
}

TEST_F(HeadingViewsCli, HeadingWithTooFewLinesExitsOne) {
  const std::string csv = (dir_ / "one.csv").string();
  std::ofstream(csv) << "u1,v1,u2,v2\n100,100,300,120\n";
  const CommandRun run = Linetrack("heading --lines " + csv + " --camera " + kCamera + " --model " +
                                   kHall + " --tilt 5 --json");
  EXPECT_EQ(run.code, 1);
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_FALSE(j["found"].get<bool>());
  EXPECT_FALSE(j["reason"].get<std::string>().empty());
}

TEST_F(HeadingViewsCli, ViewsBuildAndLocalizeOnTheRoom) {
  const std::string db = (dir_ / "views").string();
  const CommandRun build = Linetrack("views build --model " + kRoom + " --camera " + kCamera +
                                     " --grid 1.0,45 --height 1.3 --tilt 5 --out " + db);
  ASSERT_EQ(build.code, 0) << build.err;
  const nlohmann::json index = nlohmann::json::parse(ReadAll(fs::path(db) / "index.json"));
  EXPECT_EQ(index["format"], "linetrack-views");
  const int count = index["count"].get<int>();
  EXPECT_GT(count, 0);
  EXPECT_EQ(count % 8, 0);  // eight headings per position
  std::ifstream lines(fs::path(db) / "views.jsonl");
  std::string first;
  ASSERT_TRUE(std::getline(lines, first));
  const nlohmann::json view = nlohmann::json::parse(first);
  // A query from a stored view's own pose retrieves that view first.
  const RobotPose pose{view["pose"]["x"], view["pose"]["y"],
                       DegToRad(view["pose"]["heading_deg"].get<double>()), 1.3, DegToRad(5.0)};
  std::string query_line;
  RobotPose query = pose;
  for (std::string text; std::getline(lines, text);) {
    const nlohmann::json v = nlohmann::json::parse(text);
    if (v["segments"].size() >= 6) {
      query = {v["pose"]["x"], v["pose"]["y"], DegToRad(v["pose"]["heading_deg"].get<double>()),
               1.3, DegToRad(5.0)};
      query_line = text;
      break;
    }
  }
  ASSERT_FALSE(query_line.empty());
  const std::string csv = ExactLinesCsv(kRoom, query, "q.csv");
  const CommandRun run = Linetrack("views localize --lines " + csv + " --views " + db + " --json");
  EXPECT_TRUE(run.code == 0 || run.code == 1) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  ASSERT_FALSE(j["retrieved"].empty());
  EXPECT_EQ(j["retrieved"][0]["view"], nlohmann::json::parse(query_line)["id"]);
  EXPECT_EQ(run.code == 0, j["valid"].get<bool>());
}

TEST_F(HeadingViewsCli, ViewsBuildFromRenderedImages) {
  const std::string db = (dir_ / "rendered").string();
  const CommandRun build = Linetrack("views build --model " + kRoom + " --camera " + kWideCamera +
                                     " --grid 2.0,90 --render --clutter 2 --out " + db);
  ASSERT_EQ(build.code, 0) << build.err;
  EXPECT_NE(build.out.find("rendered"), std::string::npos) << build.out;
  std::ifstream lines(fs::path(db) / "views.jsonl");
  int views = 0, with_ids = 0, unknown = 0;
  for (std::string text; std::getline(lines, text); ++views) {
    const nlohmann::json view = nlohmann::json::parse(text);
    for (const auto& s : view["segments"])
      (s[4].get<int>() >= 0 ? with_ids : unknown) += 1;
  }
  EXPECT_GT(views, 0);
  // Detected lines along model edges carry the edge's id; the clutter's and the texture's none.
  EXPECT_GT(with_ids, views);
  EXPECT_GT(unknown, 0);
}

TEST_F(HeadingViewsCli, ViewsBadInputExitsTwoAndWritesNothing) {
  const std::string db = (dir_ / "views").string();
  const CommandRun grid = Linetrack("views build --model " + kRoom + " --camera " + kCamera +
                                    " --grid 0,30 --out " + db);
  EXPECT_EQ(grid.code, 2);
  EXPECT_NE(grid.err.find("--grid"), std::string::npos) << grid.err;
  EXPECT_FALSE(fs::exists(db));
  const CommandRun missing =
      Linetrack("views localize --lines x.csv --views " + (dir_ / "nothing").string());
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("index.json"), std::string::npos) << missing.err;
  fs::create_directories(db);
  ASSERT_EQ(Linetrack("views build --model " + kRoom + " --camera " + kCamera +
                      " --grid 2.0,90 --out " + db)
                .code,
            0);
  std::ofstream(fs::path(db) / "views.jsonl", std::ios::app) << "{\"id\": 99}\n";
  const std::string csv = (dir_ / "one.csv").string();
  std::ofstream(csv) << "u1,v1,u2,v2\n100,100,300,120\n";
  const CommandRun bad = Linetrack("views localize --lines " + csv + " --views " + db);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("views.jsonl:"), std::string::npos) << bad.err;
}

// The room (a door, a window, a cabinet: no symmetry) from exact lines with no prior: the truth,
// but as an unverified candidate (no image to check it on), exit 1.
TEST_F(HeadingViewsCli, LocalizeGlobalGivesTheRoomPoseFromLinesAsACandidate) {
  const std::string csv =
      ExactLinesCsv(kRoom, {1.0, 1.0, DegToRad(45.0), 1.3, DegToRad(5.0)}, "room.csv");
  const CommandRun run = Linetrack("localize --global --lines " + csv + " --model " + kRoom +
                                   " --camera " + kCamera + " --height 1.3 --tilt 5 --json");
  ASSERT_EQ(run.code, 1) << run.out << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_TRUE(j["global"].get<bool>());
  EXPECT_FALSE(j["found"].get<bool>());
  EXPECT_EQ(j["answer"], "unverified") << j;
  EXPECT_TRUE(j["pose"].is_null()) << j;
  EXPECT_FALSE(j["ambiguous"].get<bool>());
  EXPECT_TRUE(j["rivals"].empty());
  EXPECT_LT(NearestCandidateDeg(j["headings_deg"], 45.0), kHeadingTolDeg);
  ExpectPoseNear(j["candidate"], 1.0, 1.0, 45.0);
  EXPECT_EQ(j["edge_names"].size(), j["matches"].size());

  const CommandRun text = Linetrack("localize --global --lines " + csv + " --model " + kRoom +
                                    " --camera " + kCamera + " --height 1.3 --tilt 5");
  EXPECT_EQ(text.code, 1) << text.err;
  EXPECT_NE(text.out.find("heading searches"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("no answer: the candidate (x "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("--image"), std::string::npos) << text.out;
}

// A batch case without "prior", or with "prior": null, is global; one with a prior is not.
TEST_F(HeadingViewsCli, LocalizeBatchCaseWithoutPriorIsGlobal) {
  const std::string csv =
      ExactLinesCsv(kRoom, {1.0, 1.0, DegToRad(45.0), 1.3, DegToRad(5.0)}, "room.csv");
  nlohmann::json lines = nlohmann::json::array();
  std::ifstream in(csv);
  std::string row;
  std::getline(in, row);  // header
  while (std::getline(in, row)) {
    double u1, v1, u2, v2;
    char c;
    std::istringstream(row) >> u1 >> c >> v1 >> c >> u2 >> c >> v2;
    lines.push_back({u1, v1, u2, v2});
  }
  nlohmann::json base = {
      {"model", kRoom}, {"camera", kCamera}, {"height", 1.3}, {"tilt", 5.0}, {"lines", lines}};
  nlohmann::json null_prior = base, no_prior = base, prior = base;
  null_prior["id"] = "null";
  null_prior["prior"] = nullptr;
  null_prior["delta_t"] = "ignored";
  no_prior["id"] = "absent";
  prior["id"] = "local";
  prior["prior"] = {1.1, 1.1, 43.0};
  prior["delta_t"] = 0.5;
  prior["delta_phi"] = 10.0;
  const std::string batch = (dir_ / "cases.jsonl").string();
  std::ofstream(batch) << null_prior.dump() << "\n" << no_prior.dump() << "\n" << prior.dump();
  const CommandRun run = Linetrack("localize --batch " + batch);
  ASSERT_EQ(run.code, 0) << run.err;
  std::istringstream out(run.out);
  std::vector<nlohmann::json> results;
  for (std::string line; std::getline(out, line);)
    results.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(results.size(), 3u) << run.out;
  for (int i = 0; i < 2; ++i) {
    EXPECT_TRUE(results[i]["global"].get<bool>()) << results[i];
    ASSERT_FALSE(results[i]["found"].get<bool>()) << results[i];
    EXPECT_EQ(results[i]["answer"], "unverified") << results[i];
    ExpectPoseNear(results[i]["candidate"], 1.0, 1.0, 45.0);
  }
  EXPECT_EQ(results[0]["id"], "null");
  EXPECT_FALSE(results[2].contains("global")) << results[2];
  ASSERT_TRUE(results[2]["found"].get<bool>()) << results[2];
  ExpectPoseNear(results[2]["pose"], 1.0, 1.0, 45.0);
}

// An image localised with no prior goes through the same integrity gate as a local answer: the
// right pose, its protection levels beyond a 2 cm alert limit, is withheld with exit 1; within
// 0.15 m and 2 degrees (its position level is 0.11 m with the casing allowance) it is the answer.
TEST_F(HeadingViewsCli, LocalizeImageGlobalPassesTheIntegrityGate) {
  const std::string image = Render(kRoom, kCamera, "1.0,1.0,45", 5.0);
  const std::string args = "localize --global --image " + image + " --model " + kRoom +
                           " --camera " + kCamera + " --height 1.3 --tilt 5 --json";
  const CommandRun withheld = Linetrack(args + " --alert-limit 0.02,0.5");
  ASSERT_EQ(withheld.code, 1) << withheld.out << withheld.err;
  const nlohmann::json w = nlohmann::json::parse(withheld.out);
  EXPECT_TRUE(w["global"].get<bool>());
  EXPECT_FALSE(w["found"].get<bool>());
  EXPECT_TRUE(w["pose"].is_null());
  ASSERT_TRUE(w.contains("integrity")) << w;
  EXPECT_NE(w["reason"].get<std::string>().find("alert limit"), std::string::npos) << w;
  ExpectPoseNear(w["candidate"], 1.0, 1.0, 45.0);

  const CommandRun accepted = Linetrack(args + " --alert-limit 0.15,2");
  ASSERT_EQ(accepted.code, 0) << accepted.out << accepted.err;
  const nlohmann::json a = nlohmann::json::parse(accepted.out);
  EXPECT_TRUE(a["found"].get<bool>());
  EXPECT_EQ(a["integrity"]["status"], "tracking") << a;
  ExpectPoseNear(a["pose"], 1.0, 1.0, 45.0);
}

TEST_F(HeadingViewsCli, LocalizeGlobalWithAPriorIsBadInput) {
  const std::string csv = (dir_ / "one.csv").string();
  std::ofstream(csv) << "u1,v1,u2,v2\n100,100,300,120\n";
  const std::string common = "localize --global --lines " + csv + " --model " + kRoom +
                             " --camera " + kCamera + " --height 1.3 --tilt 5";
  for (const std::string flag : {" --prior 1,1,0", " --delta-t 1", " --delta-phi 10"}) {
    const CommandRun run = Linetrack(common + flag);
    EXPECT_EQ(run.code, 2) << flag;
    EXPECT_TRUE(run.out.empty()) << run.out;
    EXPECT_NE(run.err.find("--global"), std::string::npos) << run.err;
  }
  const CommandRun neither = Linetrack("localize --lines " + csv + " --model " + kRoom +
                                       " --camera " + kCamera + " --height 1.3 --tilt 5");
  EXPECT_EQ(neither.code, 2);
  EXPECT_NE(neither.err.find("--prior"), std::string::npos) << neither.err;
}

}  // namespace
}  // namespace linetrack
