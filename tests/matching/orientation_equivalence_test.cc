// A model whose faces are written the other way localises exactly as the bundled one: the hall
// and the room with every face reversed, and with a seeded half of them reversed, answer seeded
// synthetic scenes (the paper's QI2 priors) with the same poses, matches and reasons.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "matching/evaluation/diagnosis.h"
#include "matching/localizer.h"
#include "models/cao_reader.h"
#include "models/import/model_import.h"
#include "models/navigable_area.h"
#include "models/synth/synthetic_scenes.h"
#include "models/view_invariant_regions.h"
#include "tests/support/obj_export.h"
#include "tests/support/reversed_faces.h"

namespace linetrack {
namespace {

constexpr int kScenes = 40;
// The imported model's points went through Assimp's single-precision floats.
constexpr double kImportPositionTolM = 1e-3;
constexpr double kImportRotationTolDeg = 0.01;

const std::string kModels = std::string(LINETRACK_SOURCE_DIR) + "/models";

struct Matcher {
  WireframeModel model;
  NavigableArea area;
  ViewInvariantRegions regions;
  Localizer localizer;

  explicit Matcher(const CaoModel& cao)
      : model(WireframeModel::FromCao(cao)),
        area(NavigableArea::FromModel(model)),
        regions(ViewInvariantRegions::Build(model, area)),
        localizer(model, &regions, &area, PaperSyntheticCamera()) {}
};

// kScenes seeded synthetic scenes of `m` with the paper's QI2 priors.
std::vector<SyntheticScene> Qi2Scenes(const Matcher& m) {
  SyntheticSceneOptions options;
  options.count = kScenes;
  const PriorBounds qi2 = QualityIndexBounds(2);
  options.delta_t = qi2.delta_t;
  options.delta_phi = qi2.delta_phi;
  return GenerateScenes(m.model, m.area, options);
}

class Equivalence : public ::testing::TestWithParam<const char*> {};

TEST_P(Equivalence, ReversedFacesLocaliseExactlyAsWritten) {
  const CaoModel cao = ReadCao(kModels + "/" + GetParam());
  const Matcher written(cao);
  const Matcher all_reversed(test_support::ReversedFaces(cao, 1.0, 0u));
  const Matcher half_reversed(test_support::ReversedFaces(cao, 0.5, 3u));
  int found = 0;
  for (const SyntheticScene& scene : Qi2Scenes(written)) {
    const LocalizationResult a = written.localizer.Localize(ProblemOf(scene));
    found += a.found ? 1 : 0;
    for (const Matcher* other : {&all_reversed, &half_reversed}) {
      const LocalizationResult b = other->localizer.Localize(ProblemOf(scene));
      EXPECT_EQ(a.found, b.found) << "scene " << scene.index;
      EXPECT_EQ(a.cam_from_world.matrix(), b.cam_from_world.matrix()) << "scene " << scene.index;
      EXPECT_EQ(a.matches, b.matches) << "scene " << scene.index;
      EXPECT_EQ(a.candidate_edges, b.candidate_edges) << "scene " << scene.index;
      EXPECT_EQ(a.reason, b.reason) << "scene " << scene.index;
    }
  }
  EXPECT_GT(found, kScenes / 2);  // the scenes are localised, not all failures alike
}

// The hall exported as an OBJ triangle mesh (millimetres, y up) and imported again localises as
// the hand-written file: same scenes found, poses within a millimetre and a hundredth of a degree.
TEST(ImportedModel, LocalisesAsTheHandWrittenOne) {
  const CaoModel cao = ReadCao(kModels + "/hall.cao");
  const std::string obj = ::testing::TempDir() + "linetrack_equivalence_hall.obj";
  std::ofstream(obj) << test_support::ObjMillimetresYUp(cao);
  ModelImportOptions import;
  import.metres_per_unit = 1e-3;
  const Matcher written(cao);
  const Matcher imported(ImportModel(obj, import).cao);
  std::filesystem::remove(obj);
  int found = 0;
  for (const SyntheticScene& scene : Qi2Scenes(written)) {
    const LocalizationResult a = written.localizer.Localize(ProblemOf(scene));
    const LocalizationResult b = imported.localizer.Localize(ProblemOf(scene));
    found += a.found ? 1 : 0;
    EXPECT_EQ(a.found, b.found) << "scene " << scene.index;
    if (!a.found || !b.found) continue;
    const Eigen::Isometry3d delta = a.cam_from_world.inverse() * b.cam_from_world;
    EXPECT_LT(delta.translation().norm(), kImportPositionTolM) << "scene " << scene.index;
    EXPECT_LT(RadToDeg(Eigen::AngleAxisd(delta.rotation()).angle()), kImportRotationTolDeg)
        << "scene " << scene.index;
  }
  EXPECT_GT(found, kScenes / 2);
}

INSTANTIATE_TEST_SUITE_P(Models, Equivalence, ::testing::Values("hall.cao", "room.cao"),
                         [](const auto& info) {
                           std::string name = info.param;
                           return name.substr(0, name.find('.'));
                         });

}  // namespace
}  // namespace linetrack
