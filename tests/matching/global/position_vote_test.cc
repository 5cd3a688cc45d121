// The position vote of the global mode on exact synthetic scenes of the hall (no line noise, no
// calibration error, no clutter): every true correspondence's locus passes through the true
// camera position, and the accumulator's top peak at the true heading is the truth.
#include "matching/global/position_vote.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "matching/observed_line.h"
#include "models/navigable_area.h"
#include "models/synth/synthetic_scenes.h"

namespace linetrack {
namespace {

constexpr double kLocusTolM = 1e-6;  // exact lines: the locus meets the truth up to rounding
constexpr int kScenes = 30;

// Distance from p to the segment [a, b].
double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double t =
      d.squaredNorm() > 0.0 ? std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + t * d - p).norm();
}

class PositionVoteTest : public ::testing::Test {
 protected:
  PositionVoteTest()
      : model_(WireframeModel::Load(std::string(LINETRACK_SOURCE_DIR) + "/models/hall.cao")),
        area_(NavigableArea::FromModel(model_)) {
    options_.seed = 41;
    options_.count = kScenes;
    options_.angle_sigma = 0.0;
    options_.offset_sigma_px = 0.0;
    options_.calibration_sigma = 0.0;
    options_.min_clutter = options_.max_clutter = 0;
    scenes_ = GenerateScenes(model_, area_, options_);
  }

  std::vector<ObservedLine> Lines(const SyntheticScene& scene) const {
    return PrepareLines(scene.lines, options_.camera, scene.tilt, LineNoise(), 3.0);
  }

  WireframeModel model_;
  NavigableArea area_;
  SyntheticSceneOptions options_;
  std::vector<SyntheticScene> scenes_;
};

TEST_F(PositionVoteTest, EveryTrueCorrespondenceLocusPassesThroughTheTruth) {
  LocusTolerance tolerance;
  tolerance.focal_px = options_.camera.px;
  int vertical = 0, horizontal = 0;
  for (const SyntheticScene& scene : scenes_) {
    const std::vector<ObservedLine> lines = Lines(scene);
    const Eigen::Vector2d truth(scene.truth.x, scene.truth.y);
    for (const auto& [edge_id, line_index] : scene.matches) {
      const MatchEdge edge = PrepareEdges(model_, {edge_id}).front();
      const ObservedLine& line = lines[line_index];
      std::optional<PositionLocus> locus;
      if (edge.vertical) {
        locus = VerticalEdgeLocus(line, edge, scene.height, scene.truth.heading, tolerance);
        ++vertical;
      } else if (std::abs(edge.dir.z()) < 1e-9) {
        locus = HorizontalEdgeLocus(line, edge, scene.height, scene.truth.heading, tolerance);
        ++horizontal;
      } else {
        continue;  // slanted edges do not vote
      }
      ASSERT_TRUE(locus.has_value()) << "scene " << scene.index << " edge " << edge_id;
      EXPECT_LE(DistanceToSegment(truth, locus->from, locus->to), kLocusTolM)
          << "scene " << scene.index << " edge " << edge_id << (edge.vertical ? " (vertical)" : "");
    }
  }
  EXPECT_GT(vertical, 20);
  EXPECT_GT(horizontal, 50);
}

TEST_F(PositionVoteTest, TopPeakAtTheTrueHeadingIsTheTruth) {
  PositionVoteOptions vo;
  vo.tolerance.focal_px = options_.camera.px;
  const PositionVote vote(model_, area_, vo);
  // Every true line votes in the truth's cell and its neighbours: the cells within one and a half
  // cell diagonals of the truth hold the accumulator's top votes, and the first peak lies there
  // (unless another position ties with it: a scene's few lines may fit there too).
  const double tol = 1.5 * std::sqrt(2.0) * vo.cell_m;
  int first = 0;
  for (const SyntheticScene& scene : scenes_) {
    const std::vector<ObservedLine> lines = Lines(scene);
    const Eigen::Vector2d truth(scene.truth.x, scene.truth.y);
    const std::vector<float> votes = vote.Votes(lines, scene.height, scene.truth.heading);
    float top = 0.0f, at_truth = 0.0f;
    for (size_t i = 0; i < votes.size(); ++i) {
      top = std::max(top, votes[i]);
      if ((vote.CellCentre(static_cast<int>(i)) - truth).norm() <= tol)
        at_truth = std::max(at_truth, votes[i]);
    }
    EXPECT_EQ(at_truth, top) << "scene " << scene.index;
    const std::vector<PositionPeak> peaks =
        vote.Peaks(lines, scene.height, scene.truth.heading, 0.0);
    ASSERT_FALSE(peaks.empty()) << "scene " << scene.index;
    first += (peaks.front().position - truth).norm() <= tol ? 1 : 0;
  }
  EXPECT_GE(first, kScenes - 2);
}

TEST(PositionVoteOptions, CheckRejectsBadValues) {
  PositionVoteOptions o;
  std::string why;
  EXPECT_TRUE(o.Check(&why)) << why;
  o.cell_m = 0.0;
  EXPECT_FALSE(o.Check(&why));
  o = PositionVoteOptions();
  o.peaks_per_search = 0;
  EXPECT_FALSE(o.Check(&why));
}

}  // namespace
}  // namespace linetrack
