// The interpretation-tree constraints on exact projections of the hall: the true
// correspondence satisfies each equation exactly and passes each test at the noise margins.
#include "matching/constraints.h"

#include <gtest/gtest.h>

#include "scene_fixture.h"

namespace linetrack {
namespace {

constexpr double kExactTol = 1e-9;  // residual of an exact equation (unitless / metres)
constexpr double kSigmas = 3.0;     // the matcher's gate
constexpr int kViews = 200;

class ConstraintsTest : public ::testing::Test {
 protected:
  testing::HallFixture hall_;
};

// The prior disk (centre, radius delta_t) and headings heading +- delta_phi at `height`.
PriorRegion Prior(const Eigen::Vector2d& centre, double delta_t, double heading, double delta_phi,
                  double height) {
  PriorRegion prior;
  prior.centre = centre;
  prior.radius = delta_t;
  prior.heading = {heading - delta_phi, heading + delta_phi};
  prior.height = height;
  return prior;
}

std::vector<ObservedLine> Prepare(const testing::ExactView& view, const CameraIntrinsics& cam) {
  std::vector<Segment2> segments;
  for (const ProjectedEdge& p : view.pieces)
    segments.push_back(p.image);
  return PrepareLines(segments, cam, view.pose.tilt, LineNoise(), kSigmas);
}

TEST_F(ConstraintsTest, TrueCorrespondenceSolvesTheEquationsExactly) {
  std::mt19937_64 rng(7);
  for (int v = 0; v < kViews; ++v) {
    const testing::ExactView view = hall_.RandomView(rng);
    const std::vector<ObservedLine> lines = Prepare(view, hall_.camera());
    for (size_t i = 0; i < lines.size(); ++i) {
      const MatchEdge edge = PrepareEdges(hall_.model(), {view.pieces[i].edge_id}).front();
      const Eigen::Vector3d abc = DirectionCoefficients(lines[i].normal, edge.dir);
      const double h = view.pose.heading;
      EXPECT_NEAR(abc.x() * std::cos(h) + abc.y() * std::sin(h) + abc.z(), 0.0, kExactTol);
      const Eigen::Vector3d l = PositionLine(lines[i].normal, edge.mid, view.pose.height, h);
      EXPECT_NEAR(DistanceToLine(l, {view.pose.x, view.pose.y}), 0.0, kExactTol);
      if (edge.vertical) {
        EXPECT_TRUE(lines[i].maybe_vertical);
        const Eigen::Vector2d to_foot = edge.foot - Eigen::Vector2d(view.pose.x, view.pose.y);
        EXPECT_NEAR(WrapAngle(std::atan2(to_foot.y(), to_foot.x()) - (h - lines[i].bearing)), 0.0,
                    kExactTol);
      } else {
        bool found = false;
        for (double root : DirectionRoots(lines[i].normal, edge.dir)) {
          found = found || std::abs(WrapAngle(root - h)) < 1e-7;
        }
        EXPECT_TRUE(found) << "edge " << edge.edge_id;
      }
    }
  }
}

TEST_F(ConstraintsTest, UnaryAndBinaryAcceptTheTruthAtAnyPriorInsideTheBounds) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double delta_t = 0.75, delta_phi = DegToRad(20.0);
  for (int v = 0; v < kViews; ++v) {
    const testing::ExactView view = hall_.RandomView(rng);
    const std::vector<ObservedLine> lines = Prepare(view, hall_.camera());
    Eigen::Vector2d offset;
    do
      offset = {unit(rng), unit(rng)};
    while (offset.norm() > 1.0);
    const Eigen::Vector2d centre = Eigen::Vector2d(view.pose.x, view.pose.y) + delta_t * offset;
    const double heading = view.pose.heading + delta_phi * unit(rng);
    const PriorRegion prior = Prior(centre, delta_t, heading, delta_phi, view.pose.height);
    for (size_t i = 0; i < lines.size(); ++i) {
      const MatchEdge edge = PrepareEdges(hall_.model(), {view.pieces[i].edge_id}).front();
      if (edge.vertical) {
        EXPECT_TRUE(UnaryVertical(lines[i], edge, prior, Gate()).has_value());
        for (size_t j = 0; j < lines.size(); ++j) {
          const MatchEdge other = PrepareEdges(hall_.model(), {view.pieces[j].edge_id}).front();
          if (j == i || !other.vertical || other.edge_id == edge.edge_id) continue;
          EXPECT_TRUE(BinaryVertical(lines[i], lines[j],
                                     InscribedAngleRange(edge.foot, other.foot, centre, delta_t),
                                     kSigmas));
        }
      } else {
        EXPECT_FALSE(UnaryNonVertical(lines[i], edge, prior, Gate()).empty())
            << "edge " << edge.edge_id << " view " << v;
      }
    }
  }
}

}  // namespace
}  // namespace linetrack

namespace linetrack {
namespace {

// With the paper's noise the true correspondences pass the unary constraints at the 3-sigma
// margins (nearly always), and most false pairings are cut.
constexpr double kMinTruePass = 0.995;  // measured 0.998 with this seed
constexpr double kMaxFalsePass = 0.20;  // measured 0.125: a regression to "accept all" fails

TEST_F(ConstraintsTest, NoisyTruthPassesAndFalsePairingsAreCut) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double delta_t = 0.75, delta_phi = DegToRad(20.0);
  int true_pass = 0, true_total = 0, false_pass = 0, false_total = 0;
  for (int v = 0; v < kViews; ++v) {
    const testing::ExactView view = hall_.RandomView(rng);
    std::vector<Segment2> noisy;
    for (const ProjectedEdge& p : view.pieces) {
      noisy.push_back(testing::NoisySegment(p.image, 3.0, 1.0, 0.15, rng));
    }
    const std::vector<ObservedLine> lines =
        PrepareLines(noisy, hall_.camera(), view.pose.tilt, LineNoise(), kSigmas);
    Eigen::Vector2d offset;
    do
      offset = {unit(rng), unit(rng)};
    while (offset.norm() > 1.0);
    const Eigen::Vector2d centre = Eigen::Vector2d(view.pose.x, view.pose.y) + delta_t * offset;
    const double heading = view.pose.heading + delta_phi * unit(rng);
    const PriorRegion prior = Prior(centre, delta_t, heading, delta_phi, view.pose.height);
    for (size_t i = 0; i < lines.size(); ++i) {
      for (size_t j = 0; j < view.pieces.size(); ++j) {
        const MatchEdge edge = PrepareEdges(hall_.model(), {view.pieces[j].edge_id}).front();
        const bool pass = edge.vertical
                              ? lines[i].maybe_vertical &&
                                    UnaryVertical(lines[i], edge, prior, Gate()).has_value()
                              : !UnaryNonVertical(lines[i], edge, prior, Gate()).empty();
        const bool truth = view.pieces[i].edge_id == edge.edge_id;
        (truth ? true_pass : false_pass) += pass ? 1 : 0;
        (truth ? true_total : false_total) += 1;
      }
    }
  }
  const double true_rate = static_cast<double>(true_pass) / true_total;
  const double false_rate = static_cast<double>(false_pass) / false_total;
  RecordProperty("true_pass_rate", std::to_string(true_rate));
  RecordProperty("false_pass_rate", std::to_string(false_rate));
  EXPECT_GE(true_rate, kMinTruePass);
  EXPECT_LE(false_rate, kMaxFalsePass);
  std::printf("unary constraints: true pass %.4f (%d), false pass %.4f (%d)\n", true_rate,
              true_total, false_rate, false_total);
}

}  // namespace
}  // namespace linetrack
