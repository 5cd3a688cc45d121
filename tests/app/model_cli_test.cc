// Loading a model from the command line: `model-info` says what orienting the faces turned and
// what the checks found; a finding is a warning on stderr, and under `--strict` a refusal (exit 2,
// one line naming the file); `localize --storey` names a storey the model does not have;
// `model-import` writes the hall back from an OBJ mesh and refuses bad input without output.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "models/cao_reader.h"
#include "models/cao_writer.h"
#include "tests/support/cli_test.h"
#include "tests/support/obj_export.h"

namespace linetrack {
namespace {

const std::string kHall = std::string(LINETRACK_SOURCE_DIR) + "/models/hall.cao";

class ModelCli : public test_support::CliTest {
 protected:
  // The hall written to the test's folder, changed by `change`.
  template <typename Change>
  std::string WriteHall(const std::string& name, Change change) const {
    CaoModel cao = ReadCao(kHall);
    change(&cao);
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << CaoText(cao, name);
    return path;
  }
};
using test_support::CommandRun;

TEST_F(ModelCli, ModelInfoSaysWhatItTurned) {
  const std::string reversed = WriteHall("reversed.cao", [](CaoModel* cao) {
    for (std::vector<int>& face : cao->faces)
      std::reverse(face.begin(), face.end());
  });
  const CommandRun run = Linetrack("model-info " + reversed + " --queries 0");
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find("wall faces turned to face the room"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("obstacle faces turned outward"), std::string::npos) << run.out;
  // The same area as the bundled hall's (tests/app: app.ModelInfoHall).
  EXPECT_NE(run.out.find("124.80 m2 from walls"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("checks                 nothing found"), std::string::npos) << run.out;

  const CommandRun as_written = Linetrack("model-info " + kHall + " --queries 0 --json");
  ASSERT_EQ(as_written.code, 0) << as_written.err;
  const nlohmann::json info = nlohmann::json::parse(as_written.out);
  EXPECT_TRUE(info["orientation"].empty()) << info["orientation"];
  EXPECT_TRUE(info["findings"].empty()) << info["findings"];
}

TEST_F(ModelCli, AStrayLineWarnsAndStrictRefuses) {
  // A door jamb 0.3 m in front of the south wall (y = 0), on no face.
  const std::string stray = WriteHall("stray.cao", [](CaoModel* cao) {
    const int n = static_cast<int>(cao->points.size());
    cao->points.push_back({7.0, 0.3, 0.0});
    cao->points.push_back({7.0, 0.3, 2.1});
    cao->lines.push_back({n, n + 1});
  });
  const CommandRun warned = Linetrack("model-info " + stray + " --queries 0");
  ASSERT_EQ(warned.code, 0) << warned.err;
  EXPECT_NE(warned.err.find("lies on no face"), std::string::npos) << warned.err;
  EXPECT_NE(warned.out.find("1 finding\n"), std::string::npos) << warned.out;

  for (const std::string& args :
       {"--strict model-info " + stray, "model-info " + stray + " --strict"}) {
    const CommandRun refused = Linetrack(args);
    EXPECT_EQ(refused.code, 2) << args;
    EXPECT_NE(refused.err.find("stray.cao"), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find("--strict"), std::string::npos) << refused.err;
    EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
    EXPECT_TRUE(refused.out.empty()) << refused.out;
  }
  // The bundled hall passes under --strict.
  EXPECT_EQ(Linetrack("--strict model-info " + kHall + " --queries 0").code, 0);
}

TEST_F(ModelCli, ModelImportWritesTheHallBackAndRefusesBadInput) {
  const std::string obj = (dir_ / "hall.obj").string();
  std::ofstream(obj) << test_support::ObjMillimetresYUp(ReadCao(kHall));
  const std::string out = (dir_ / "imported.cao").string();
  const CommandRun run = Linetrack("model-import " + obj + " --out " + out + " --unit mm");
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find("15 faces, 20 3D lines, 66 edges (28 vertical)"), std::string::npos)
      << run.out;
  EXPECT_TRUE(run.err.empty()) << run.err;
  const CommandRun info = Linetrack("--strict model-info " + out + " --queries 0");
  EXPECT_EQ(info.code, 0) << info.err;

  const std::string garbage = (dir_ / "garbage.obj").string();
  std::ofstream(garbage) << "not a model\n";
  const std::string refused_out = (dir_ / "refused.cao").string();
  for (const std::string& args :
       {"model-import " + garbage + " --out " + refused_out,
        "model-import " + (dir_ / "missing.obj").string() + " --out " + refused_out,
        "model-import " + obj + " --out " + refused_out + " --unit inch",
        "model-import " + obj + " --out " + refused_out + " --feature-angle 120"}) {
    const CommandRun refused = Linetrack(args);
    EXPECT_EQ(refused.code, 2) << args;
    EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
    EXPECT_FALSE(std::filesystem::exists(refused_out)) << args;
  }
}

TEST_F(ModelCli, LocalizeRefusesAStoreyTheModelDoesNotHave) {
  const std::string synth = (dir_ / "synth").string();
  ASSERT_EQ(Linetrack("synth --model " + kHall + " --out " + synth + " --count 1").code, 0);
  std::ifstream cases(synth + "/cases.jsonl");
  std::string row;
  std::getline(cases, row);
  const nlohmann::json c = nlohmann::json::parse(row);
  std::ofstream csv(dir_ / "lines.csv");
  for (const auto& l : c["lines"])
    csv << l[0] << "," << l[1] << "," << l[2] << "," << l[3] << "\n";
  csv.close();
  std::ostringstream args;
  args << "localize --model " << kHall << " --camera " << synth << "/camera.xml --lines "
       << (dir_ / "lines.csv").string() << " --prior " << c["prior"][0] << "," << c["prior"][1]
       << "," << c["prior"][2] << " --delta-t " << c["delta_t"] << " --delta-phi " << c["delta_phi"]
       << " --height " << c["height"] << " --tilt " << c["tilt"] << " --json";
  const CommandRun plain = Linetrack(args.str());
  const CommandRun storey0 = Linetrack(args.str() + " --storey 0");
  ASSERT_TRUE(plain.code == 0 || plain.code == 1) << plain.err;
  EXPECT_EQ(storey0.code, plain.code) << storey0.err;
  const nlohmann::json a = nlohmann::json::parse(plain.out), b = nlohmann::json::parse(storey0.out);
  EXPECT_EQ(a["cMo"], b["cMo"]);
  EXPECT_EQ(a["matches"], b["matches"]);

  const CommandRun missing = Linetrack(args.str() + " --storey 3");
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("storey"), std::string::npos) << missing.err;
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;
  EXPECT_TRUE(missing.out.empty()) << missing.out;
}

}  // namespace
}  // namespace linetrack
