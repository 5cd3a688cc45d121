// `linetrack localize` end to end: a batch mixing good and malformed cases answers every case in
// order (malformed ones with an `error`, the others localised), an unreadable batch exits 2 with
// one line, and the single-case form prints the batch's JSON keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/support/cli_test.h"

namespace linetrack {
namespace {

const std::string kSource = LINETRACK_SOURCE_DIR;

class LocalizeCli : public test_support::CliTest {};
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
        << variant("missing-prior", [](nlohmann::json& j) { j.erase("prior"); }) << "\n"
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
      {"missing-prior", "prior"},
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
  for (const auto& l : c["lines"])
    csv << l[0] << "," << l[1] << "," << l[2] << "," << l[3] << "\n";
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

}  // namespace
}  // namespace linetrack
