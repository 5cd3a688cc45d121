// Localisation with no prior: the searches planned from heading candidates, and a room that is
// the same after a half turn about its centre, where every answer must be "ambiguous".
#include "matching/global/global_localizer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "matching/heading/model_directions.h"
#include "models/cao_reader.h"
#include "models/navigable_area.h"
#include "models/synth/synthetic_scenes.h"

namespace linetrack {
namespace {

constexpr double kPositionTolM = 0.3;  // a correct answer (the benchmarks' tolerance)
constexpr double kHeadingTolDeg = 3.0;
constexpr double kAngleTol = 1e-12;

bool Near(const Pose3Dof& a, const Pose3Dof& b) {
  return std::hypot(a.x - b.x, a.y - b.y) <= kPositionTolM &&
         std::abs(RadToDeg(WrapAngle(a.heading - b.heading))) <= kHeadingTolDeg;
}

TEST(PlanHeadingSearches, EveryHeadingOfTheKeptPeaksWithItsClampedBound) {
  HeadingCandidates c;
  c.found = true;
  HeadingHypothesis strong, weak, weaker;
  strong.headings = {0.1, 0.1 + kPi / 2, 0.1 + kPi, 0.1 + 3 * kPi / 2};
  strong.heading_sigma = DegToRad(0.1);  // 3 sigma below the minimum bound
  strong.support = 10;
  weak.headings = {0.5, 0.5 + kPi};
  weak.heading_sigma = DegToRad(1.0);  // 3 sigma inside the bounds
  weak.support = 6;
  weaker = weak;
  weaker.support = 3;  // below half the best support
  c.hypotheses = {strong, weak, weaker};
  GlobalOptions options;
  options.max_heading_hypotheses = 3;
  const std::vector<HeadingSearch> plan = PlanHeadingSearches(c, options);
  ASSERT_EQ(plan.size(), 6u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(plan[i].heading, strong.headings[i], kAngleTol);
    EXPECT_NEAR(plan[i].heading_bound, DegToRad(options.min_heading_bound_deg), kAngleTol);
  }
  EXPECT_NEAR(plan[4].heading, 0.5, kAngleTol);
  EXPECT_NEAR(plan[5].heading_bound, DegToRad(3.0), kAngleTol);
  options.max_heading_hypotheses = 1;
  EXPECT_EQ(PlanHeadingSearches(c, options).size(), 4u);
  c.found = false;
  EXPECT_TRUE(PlanHeadingSearches(c, options).empty());
}

TEST(VerifierOptions, TheSearchBudgetsAreTheSharedOnesScaledAtLeastOne) {
  LocalizerOptions local;
  local.tree.max_nodes = 5000;
  local.tree.max_checks = 100000;
  local.tree.max_hypotheses = 2;
  local.verification.max_pair_tests = 800000;
  GlobalOptions options;
  options.verify_budget_share = 0.3;
  const LocalizerOptions v = VerifierOptions(local, options);
  EXPECT_EQ(v.tree.max_nodes, 1500);
  EXPECT_EQ(v.tree.max_checks, 30000);
  EXPECT_EQ(v.tree.max_hypotheses, 1);  // 0.6 leaves: at least one
  EXPECT_EQ(v.verification.max_pair_tests, 240000);
  EXPECT_EQ(v.tree.max_lines, local.tree.max_lines);  // not a budget: unchanged
  options.verify_budget_share = 0.0;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
}

TEST(GlobalOptions, CheckRejectsBadBounds) {
  GlobalOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why)) << why;
  options.max_heading_bound_deg = 1.0;  // below the minimum
  EXPECT_FALSE(options.Check(&why));
  options = GlobalOptions();
  options.max_heading_hypotheses = 0;
  EXPECT_FALSE(options.Check(&why));
}

// A 6 x 4 m room with a door in the south wall and its copy, turned half a turn about the
// room's centre (3, 2), in the north wall: every view has a twin.
constexpr const char* kSymmetricRoom = R"(V1
16
0 0 0
0 0 2.5
6 0 2.5
6 0 0
6 4 2.5
6 4 0
0 4 2.5
0 4 0
1 0 0
1 0 2
2 0 2
2 0 0
5 4 0
5 4 2
4 4 2
4 4 0
6
8 9
9 10
10 11
12 13
13 14
14 15
0
4
4 0 1 2 3
4 3 2 4 5
4 5 4 6 7
4 7 6 1 0
0
)";

TEST(GlobalLocalizer, ARoomThatRepeatsAfterAHalfTurnIsAmbiguousNeverPicked) {
  const auto no_include = [](const std::string&) -> std::optional<std::string> {
    return std::nullopt;
  };
  const WireframeModel model =
      WireframeModel::FromCao(ParseCao(kSymmetricRoom, "symmetric.cao", no_include));
  const NavigableArea area = NavigableArea::FromModel(model);
  SyntheticSceneOptions so;
  so.seed = 5;
  so.count = 6;
  so.min_clutter = so.max_clutter = 0;
  so.min_visible_edges = 5;
  const std::vector<SyntheticScene> scenes = GenerateScenes(model, area, so);
  const Localizer localizer(model, nullptr, &area, so.camera);
  const ModelDirections directions = DominantDirections(model);
  const GlobalLocalizer global(localizer, directions, GlobalOptionsFor(localizer.options()));
  int ambiguous = 0;
  for (const SyntheticScene& scene : scenes) {
    const GlobalResult r = global.Localize({scene.lines, scene.height, scene.tilt});
    EXPECT_FALSE(r.found) << "scene " << scene.index << ": picked one of two twins";
    if (!r.ambiguous) continue;
    ++ambiguous;
    // The truth and its twin (the half turn about the centre) are among the rivals.
    Pose3Dof twin{6.0 - scene.truth.x, 4.0 - scene.truth.y, scene.truth.heading + kPi};
    const auto listed = [&](const Pose3Dof& p) {
      return std::any_of(r.rivals.begin(), r.rivals.end(),
                         [&](const Pose3Dof& q) { return Near(q, p); });
    };
    EXPECT_TRUE(listed(scene.truth.Planar()) && listed(twin)) << "scene " << scene.index;
  }
  EXPECT_GE(ambiguous, 1);
}

}  // namespace
}  // namespace linetrack
