// `linetrack localize` end to end: a batch mixing good and malformed cases answers every case in
// order (malformed ones with an `error`, the others localised) and echoes each id as given, an
// unreadable batch exits 2 with one line, and the single-case form prints the batch's JSON keys,
// takes replay's prior bounds by default, names the matched edges, reads a ROS camera_info as
// its camera and refuses bad heights and flags that cannot apply. The global mode (no prior): a
// batch case with "prior": null and the --global flags give a case's true pose as an unverified
// candidate, and --global with a prior is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/support/cli_test.h"

namespace linetrack {
namespace {

const std::string kSource = LINETRACK_SOURCE_DIR;

class LocalizeCli : public test_support::CliTest {};

// Writes a case's "lines" ([[u1, v1, u2, v2], ...]) as CSV rows, one segment each.
void WriteSegmentRows(const nlohmann::json& lines, std::ostream& csv) {
  for (const auto& l : lines)
    csv << l[0] << "," << l[1] << "," << l[2] << "," << l[3] << "\n";
}
using test_support::CommandRun;

TEST_F(LocalizeCli, MalformedCasesGetAnErrorAndTheOthersAreAnswered) {
  const std::string synth = (dir_ / "synth").string();
  ASSERT_EQ(Linetrack("synth --model " + kSource + "/models/hall.cao --out " + synth +
                      " --count 2 --qi 1")
                .code,
            0);
  std::ifstream cases(synth + "/cases.jsonl");
  std::string good1, good2;
  std::getline(cases, good1);
  std::getline(cases, good2);
  nlohmann::json base = nlohmann::json::parse(good1);
  base["model"] = kSource + "/models/hall.cao";
  base["camera"] = synth + "/camera.xml";
  auto variant = [&](const std::string& id, auto change) {
    nlohmann::json j = base;
    j["id"] = id;
    change(j);
    return j.dump();
  };
  std::ofstream batch(dir_ / "batch.jsonl");
  batch << base.dump() << "\n"
        << variant("empty-lines", [](nlohmann::json& j) { j["lines"] = nlohmann::json::array(); })
        << "\n"
        << variant("nan", [](nlohmann::json& j) { j["lines"][0][1] = "nan"; }) << "\n"
        << variant("zero-length",
                   [](nlohmann::json& j) {
                     j["lines"][1] = {10.0, 20.0, 10.0, 20.0};
                   })
        << "\n"
        << variant("unknown-model", [](nlohmann::json& j) { j["model"] = "/nonexistent.cao"; })
        << "\n"
        << variant("bad-prior",
                   [](nlohmann::json& j) {
                     j["prior"] = {1.0, 2.0};
                   })
        << "\n"
        << variant("missing-tilt", [](nlohmann::json& j) { j.erase("tilt"); }) << "\n"
        << "\n"  // blank: skipped
        << "{\"id\": \"not-json\", \"lines\": [1, 2,\n"
        << "[1, 2, 3]\n";
  nlohmann::json second = nlohmann::json::parse(good2);
  second["model"] = base["model"];
  second["camera"] = base["camera"];
  batch << second.dump() << "\n";
  batch.close();

  const CommandRun run = Linetrack("localize --batch " + (dir_ / "batch.jsonl").string());
  ASSERT_EQ(run.code, 0) << run.err;
  std::istringstream rows(run.out);
  std::vector<nlohmann::json> results;
  for (std::string row; std::getline(rows, row);)
    results.push_back(nlohmann::json::parse(row));
  const std::vector<std::pair<std::string, std::string>> expected = {
      {base["id"], ""},
      {"empty-lines", "no line segments"},
      {"nan", "not a number"},
      {"zero-length", "zero-length"},
      {"unknown-model", "/nonexistent.cao"},
      {"bad-prior", "prior"},
      {"missing-tilt", "tilt"},
      {"line-9", "not valid JSON"},
      {"line-10", "JSON object"},
      {second["id"], ""},
  };
  ASSERT_EQ(results.size(), expected.size()) << run.out;
  for (size_t i = 0; i < expected.size(); ++i) {
    const auto& [id, error] = expected[i];
    EXPECT_EQ(results[i]["id"], id);
    if (error.empty()) {
      EXPECT_FALSE(results[i].contains("error")) << results[i].dump();
      for (const char* key :
           {"found", "pose", "cMo", "matches", "score", "hypotheses", "time_ms"}) {
        EXPECT_TRUE(results[i].contains(key)) << key;
      }
    } else {
      ASSERT_TRUE(results[i].contains("error")) << results[i].dump();
      EXPECT_FALSE(results[i]["found"].get<bool>());
      EXPECT_NE(results[i]["error"].get<std::string>().find(error), std::string::npos)
          << results[i]["error"];
    }
  }
}

TEST_F(LocalizeCli, UnreadableBatchExitsTwoWithOneLine) {
  for (const std::string& path : {std::string("/nonexistent/batch.jsonl"), dir_.string()}) {
    const CommandRun run = Linetrack("localize --batch " + path);
    EXPECT_EQ(run.code, 2) << path;
    EXPECT_NE(run.err.find(path), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_TRUE(run.out.empty()) << run.out;
  }
}

TEST_F(LocalizeCli, SingleCasePrintsTheBatchKeysOrFailsCleanly) {
  const std::string synth = (dir_ / "synth").string();
  ASSERT_EQ(
      Linetrack("synth --model " + kSource + "/models/hall.cao --out " + synth + " --count 1").code,
      0);
  std::ifstream cases(synth + "/cases.jsonl");
  std::string row;
  std::getline(cases, row);
  const nlohmann::json c = nlohmann::json::parse(row);
  std::ofstream csv(dir_ / "lines.csv");
  csv << "u1,v1,u2,v2\n";
  WriteSegmentRows(c["lines"], csv);
  csv.close();
  std::ostringstream args;
  args << "localize --model " << kSource << "/models/hall.cao --camera " << synth
       << "/camera.xml --lines " << (dir_ / "lines.csv").string() << " --prior " << c["prior"][0]
       << "," << c["prior"][1] << "," << c["prior"][2] << " --delta-t " << c["delta_t"]
       << " --delta-phi " << c["delta_phi"] << " --height " << c["height"] << " --tilt "
       << c["tilt"] << " --json";
  const CommandRun run = Linetrack(args.str());
  ASSERT_TRUE(run.code == 0 || run.code == 1) << run.err;
  const nlohmann::json result = nlohmann::json::parse(run.out);
  EXPECT_EQ(result["found"].get<bool>(), run.code == 0);
  EXPECT_TRUE(result.contains("cMo") && result.contains("matches") && result.contains("time_ms"));

  // A NaN in the CSV: exit 2, one line naming the file.
  std::ofstream bad(dir_ / "bad.csv");
  bad << "1,2,3,4\nnan,2,3,4\n";
  bad.close();
  std::string bad_args = args.str();
  bad_args.replace(bad_args.find((dir_ / "lines.csv").string()),
                   (dir_ / "lines.csv").string().size(), (dir_ / "bad.csv").string());
  const CommandRun failed = Linetrack(bad_args);
  EXPECT_EQ(failed.code, 2);
  EXPECT_NE(failed.err.find("bad.csv"), std::string::npos) << failed.err;
  EXPECT_EQ(std::count(failed.err.begin(), failed.err.end(), '\n'), 1) << failed.err;
}

// A synthetic QI3 case of the hall as a lines CSV, and the flags that state it (but the bounds,
// which are QI3's: the defaults).
struct SingleCase {
  nlohmann::json json;
  std::string synth, flags;
};

class LocalizeSingleCli : public LocalizeCli {
 protected:
  SingleCase MakeSingleCase() {
    const std::filesystem::path& dir = dir_;
    SingleCase sc;
    sc.synth = (dir / "synth").string();
    EXPECT_EQ(Linetrack("synth --model " + kSource + "/models/hall.cao --out " + sc.synth +
                        " --count 1 --qi 3")
                  .code,
              0);
    std::ifstream cases(sc.synth + "/cases.jsonl");
    std::string row;
    std::getline(cases, row);
    sc.json = nlohmann::json::parse(row);
    std::ofstream csv(dir / "lines.csv");
    WriteSegmentRows(sc.json["lines"], csv);
    std::ostringstream flags;
    flags << "--model " << kSource << "/models/hall.cao --lines " << (dir / "lines.csv").string()
          << " --prior " << sc.json["prior"][0] << "," << sc.json["prior"][1] << ","
          << sc.json["prior"][2] << " --height " << sc.json["height"] << " --tilt "
          << sc.json["tilt"];
    sc.flags = flags.str();
    return sc;
  }
};

// The result JSON without its time.
nlohmann::json Untimed(const std::string& out) {
  nlohmann::json j = nlohmann::json::parse(out);
  j.erase("time_ms");
  return j;
}

TEST_F(LocalizeSingleCli, BoundsDefaultToReplaysAndMatchesShowEdgeNames) {
  const SingleCase sc = MakeSingleCase();
  ASSERT_NEAR(sc.json["delta_t"].get<double>(), 0.75, 1e-12);  // QI3 = replay's defaults
  ASSERT_NEAR(sc.json["delta_phi"].get<double>(), 20.0, 1e-9);
  const std::string camera = " --camera " + sc.synth + "/camera.xml";
  const CommandRun defaults = Linetrack("localize " + sc.flags + camera + " --json");
  const CommandRun explicit_bounds =
      Linetrack("localize " + sc.flags + camera + " --delta-t 0.75 --delta-phi 20 --json");
  ASSERT_EQ(defaults.code, 0) << defaults.err;
  ASSERT_EQ(explicit_bounds.code, 0) << explicit_bounds.err;
  const nlohmann::json result = Untimed(defaults.out);
  EXPECT_EQ(result, Untimed(explicit_bounds.out));
  // Every match's edge has a name in the hall (its .cao names lines and faces).
  ASSERT_EQ(result["edge_names"].size(), result["matches"].size());
  for (const auto& name : result["edge_names"])
    EXPECT_FALSE(name.get<std::string>().empty()) << result.dump();

  const CommandRun text = Linetrack("localize " + sc.flags + camera);
  ASSERT_EQ(text.code, 0) << text.err;
  const std::string first = result["edge_names"][0].get<std::string>();
  EXPECT_NE(text.out.find(" " + first + " <- line "), std::string::npos) << text.out;
}

TEST_F(LocalizeSingleCli, RosAndOpenCvYamlAreTheSameCameraAsTheXml) {
  const SingleCase sc = MakeSingleCase();
  // The paper's camera of synth's camera.xml as ROS's camera_calibration_parsers write it.
  std::ofstream(dir_ / "camera_info.yaml")
      << "image_width: 640\nimage_height: 480\ncamera_name: Camera\n"
      << "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [1000, 0, 320, 0, 1000, 240, 0, 0, 1]\n"
      << "distortion_model: plumb_bob\ndistortion_coefficients:\n  rows: 1\n  cols: 5\n"
      << "  data: [0, 0, 0, 0, 0]\n";
  // The same camera as OpenCV's FileStorage writes it (calibrate's opencv.yml).
  std::ofstream(dir_ / "opencv.yml")
      << "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n"
      << "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
      << "   data: [ 1000., 0., 320., 0., 1000., 240., 0., 0., 1. ]\n"
      << "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n"
      << "   data: [ 0., 0., 0., 0., 0. ]\n";
  const CommandRun xml =
      Linetrack("localize " + sc.flags + " --camera " + sc.synth + "/camera.xml --json");
  const CommandRun ros = Linetrack("localize " + sc.flags + " --camera " +
                                   (dir_ / "camera_info.yaml").string() + " --json");
  const CommandRun opencv =
      Linetrack("localize " + sc.flags + " --camera " + (dir_ / "opencv.yml").string() + " --json");
  ASSERT_EQ(xml.code, 0) << xml.err;
  ASSERT_EQ(ros.code, 0) << ros.err;
  ASSERT_EQ(opencv.code, 0) << opencv.err;
  EXPECT_EQ(Untimed(xml.out), Untimed(ros.out));
  EXPECT_EQ(Untimed(xml.out), Untimed(opencv.out));
}

TEST_F(LocalizeSingleCli, ANonPositiveHeightIsBadInput) {
  const SingleCase sc = MakeSingleCase();
  std::string flags = sc.flags;
  const size_t at = flags.find("--height ");
  flags.erase(at, flags.find(' ', at + 9) - at);  // drop the case's own height
  for (const std::string height : {"-1", "0", "nan"}) {
    const CommandRun run =
        Linetrack("localize " + flags + " --camera " + sc.synth + "/camera.xml --height " + height);
    EXPECT_EQ(run.code, 2) << height << ": " << run.err;
    EXPECT_NE(run.err.find("--height"), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_TRUE(run.out.empty()) << run.out;
  }
}

TEST_F(LocalizeSingleCli, BatchIdsComeBackAsGiven) {
  const SingleCase sc = MakeSingleCase();
  nlohmann::json c = sc.json;
  c["model"] = kSource + "/models/hall.cao";
  c["camera"] = sc.synth + "/camera.xml";
  std::ofstream batch(dir_ / "ids.jsonl");
  for (const nlohmann::json& id :
       {nlohmann::json(7), nlohmann::json("seven"), nlohmann::json(2.5)}) {
    c["id"] = id;
    batch << c.dump() << "\n";
  }
  c["id"] = 9;
  c["height"] = -1.0;  // an error result keeps its id too
  batch << c.dump() << "\n";
  batch.close();
  const CommandRun run = Linetrack("localize --batch " + (dir_ / "ids.jsonl").string());
  ASSERT_EQ(run.code, 0) << run.err;
  std::istringstream rows(run.out);
  std::vector<nlohmann::json> results;
  for (std::string row; std::getline(rows, row);)
    results.push_back(nlohmann::json::parse(row));
  ASSERT_EQ(results.size(), 4u) << run.out;
  EXPECT_TRUE(results[0]["id"].is_number_integer());
  EXPECT_EQ(results[0]["id"], 7);
  EXPECT_EQ(results[1]["id"], "seven");
  EXPECT_EQ(results[2]["id"], 2.5);
  EXPECT_EQ(results[3]["id"], 9);
  EXPECT_NE(results[3]["error"].get<std::string>().find("\"height\""), std::string::npos)
      << results[3].dump();
}

TEST_F(LocalizeSingleCli, FlagsThatCannotApplyAreRefused) {
  const SingleCase sc = MakeSingleCase();
  const std::string camera = " --camera " + sc.synth + "/camera.xml";
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"localize --batch " + (dir_ / "b.jsonl").string() + " --tilt 5", "--tilt"},
      {"localize " + sc.flags + camera + " --detector lsd", "--detector"},
      {"localize " + sc.flags + camera + " --overlay " + (dir_ / "o.png").string(), "--overlay"},
      {"localize --model m.cao --camera c.xml --lines l.csv --prior 1,2,3 --height 1", "--tilt"},
  };
  for (const auto& [args, flag] : refused) {
    const CommandRun run = Linetrack(args);
    EXPECT_EQ(run.code, 2) << args;
    EXPECT_NE(run.err.find(flag), std::string::npos) << run.err;
    EXPECT_EQ(run.err.find("is required is required"), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  }
}

TEST_F(LocalizeSingleCli, GlobalFlagsWorkAfterTheSubcommand) {
  const SingleCase sc = MakeSingleCase();
  const std::string args = sc.flags + " --camera " + sc.synth + "/camera.xml";
  const CommandRun loud = Linetrack("localize " + args);
  const CommandRun before = Linetrack("-q localize " + args);
  const CommandRun after = Linetrack("localize " + args + " -q");
  ASSERT_EQ(loud.code, 0) << loud.err;
  EXPECT_EQ(before.code, 0) << before.err;
  EXPECT_EQ(after.code, 0) << after.err;
  EXPECT_TRUE(after.err.empty()) << after.err;
  EXPECT_EQ(after.err, before.err);
  const CommandRun unknown = Linetrack("localize " + args + " --no-such-flag");
  EXPECT_EQ(unknown.code, 2);
  EXPECT_NE(unknown.err.find("--no-such-flag"), std::string::npos) << unknown.err;
}

// A pose of the global mode this close to the truth is correct (the benchmarks' tolerance,
// app/match_outcome.h).
constexpr double kGlobalPositionTolM = 0.5;
constexpr double kGlobalHeadingTolDeg = 5.0;

// Scene 4 of the hall's synthetic scenes of seed 17: `bench match --series global` answers it
// with a clear margin (docs/global.md). Its case with "prior": null, and its truth.
struct GlobalCase {
  nlohmann::json json, truth;
  std::string synth;
};

class LocalizeGlobalCli : public LocalizeCli {
 protected:
  GlobalCase MakeGlobalCase() {
    GlobalCase gc;
    gc.synth = (dir_ / "synth").string();
    EXPECT_EQ(Linetrack("synth --model " + kSource + "/models/hall.cao --out " + gc.synth +
                        " --count 5 --seed 17")
                  .code,
              0);
    std::ifstream cases(gc.synth + "/cases.jsonl"), truths(gc.synth + "/truth.jsonl");
    std::string row, truth;
    for (int i = 0; i < 5; ++i) {
      std::getline(cases, row);
      std::getline(truths, truth);
    }
    gc.json = nlohmann::json::parse(row);
    gc.json["prior"] = nullptr;
    gc.truth = nlohmann::json::parse(truth)["pose"];
    return gc;
  }

  // A global answer from lines alone: no pose, but its unverified candidate within the
  // tolerance of the truth.
  static void ExpectCandidateAtTheTruth(const nlohmann::json& result, const nlohmann::json& truth) {
    ASSERT_FALSE(result["found"].get<bool>()) << result.dump();
    EXPECT_TRUE(result["global"].get<bool>());
    EXPECT_EQ(result["answer"], "unverified") << result.dump();
    EXPECT_TRUE(result["pose"].is_null()) << result.dump();
    const nlohmann::json& pose = result["candidate"];
    EXPECT_LE(std::hypot(pose["x"].get<double>() - truth["x"].get<double>(),
                         pose["y"].get<double>() - truth["y"].get<double>()),
              kGlobalPositionTolM)
        << result.dump();
    const double heading = std::remainder(
        pose["heading_deg"].get<double>() - truth["heading_deg"].get<double>(), 360.0);
    EXPECT_LE(std::abs(heading), kGlobalHeadingTolDeg) << result.dump();
  }
};

TEST_F(LocalizeGlobalCli, BatchCaseWithANullPriorGivesTheTruthAsACandidate) {
  const GlobalCase gc = MakeGlobalCase();
  nlohmann::json c = gc.json;
  c["delta_t"] = "ignored";                             // the bounds are ignored without a prior
  const std::string path = gc.synth + "/global.jsonl";  // beside the case's camera
  std::ofstream batch(path);
  batch << c.dump() << "\n";
  batch.close();
  const CommandRun run = Linetrack("localize --batch " + path);
  ASSERT_EQ(run.code, 0) << run.err;
  ExpectCandidateAtTheTruth(nlohmann::json::parse(run.out), gc.truth);
}

TEST_F(LocalizeGlobalCli, GlobalFlagGivesTheTruthAsACandidateAndRefusesAPrior) {
  const GlobalCase gc = MakeGlobalCase();
  std::ofstream csv(dir_ / "lines.csv");
  WriteSegmentRows(gc.json["lines"], csv);
  csv.close();
  std::ostringstream flags;
  flags << "localize --global --model " << kSource << "/models/hall.cao --camera " << gc.synth
        << "/camera.xml --lines " << (dir_ / "lines.csv").string() << " --height "
        << gc.json["height"] << " --tilt " << gc.json["tilt"];
  const CommandRun run = Linetrack(flags.str() + " --json");
  ASSERT_EQ(run.code, 1) << run.err;
  ExpectCandidateAtTheTruth(nlohmann::json::parse(run.out), gc.truth);
  for (const std::string flag : {"--prior 1,2,3", "--delta-t 1", "--delta-phi 10"}) {
    const CommandRun refused = Linetrack(flags.str() + " " + flag);
    EXPECT_EQ(refused.code, 2) << flag;
    EXPECT_NE(refused.err.find(flag.substr(0, flag.find(' '))), std::string::npos) << refused.err;
    EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  }
}

}  // namespace
}  // namespace linetrack
