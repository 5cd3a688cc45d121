// A localisation without a candidate edge says why in its reason: the prior outside the
// navigable area, or an empty list given.
#include <gtest/gtest.h>

#include "matching/localizer.h"
#include "models/navigable_area.h"
#include "models/synth/synthetic_scenes.h"
#include "models/view_invariant_regions.h"

namespace linetrack {
namespace {

TEST(NoCandidateReason, PriorOutsideTheNavigableArea) {
  const WireframeModel model =
      WireframeModel::Load(std::string(LINETRACK_SOURCE_DIR) + "/models/hall.cao");
  const NavigableArea area = NavigableArea::FromModel(model);
  const ViewInvariantRegions regions = ViewInvariantRegions::Build(model, area);
  const Localizer localizer(model, &regions, &area, PaperSyntheticCamera());
  LocalizationProblem problem;
  problem.lines = {{{100.0, 100.0}, {300.0, 120.0}}, {{320.0, 50.0}, {330.0, 400.0}}};
  problem.prior = {-20.0, -20.0, 0.0};
  problem.delta_t = 0.5;
  problem.delta_phi = DegToRad(15.0);
  problem.height = 1.3;
  const LocalizationResult outside = localizer.Localize(problem);
  EXPECT_FALSE(outside.found);
  EXPECT_EQ(outside.candidate_edges, 0);
  EXPECT_EQ(outside.reason,
            "no candidate edge: the prior (-20.00, -20.00) +- 0.50 m lies outside the navigable "
            "area");
  problem.prior = {7.0, 2.0, 0.0};
  problem.candidate_edges = std::vector<int>();
  EXPECT_EQ(localizer.Localize(problem).reason, "no candidate edge: the given list is empty");
}

}  // namespace
}  // namespace linetrack
