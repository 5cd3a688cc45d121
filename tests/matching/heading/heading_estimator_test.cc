// EstimateHeading on exact projections (the heading and tilt are recovered to numerical
// precision), on noisy segments with clutter, and on a building without a quarter-turn symmetry
// (the candidates are then the heading and its half turn).
#include "matching/heading/heading_estimator.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "matching/heading/heading_vote.h"
#include "matching/heading/vanishing_geometry.h"
#include "models/errors.h"
#include "models/robot_pose.h"
#include "tests/matching/scene_fixture.h"

namespace linetrack {
namespace {

constexpr double kExactHeadingTolDeg = 1e-6;  // exact projections: numerical precision
constexpr double kExactTiltTolDeg = 1e-6;
constexpr double kNoisyHeadingTolDeg = 1.0;  // the target for one candidate
constexpr double kNoisyMedianTolDeg = 0.5;
constexpr double kNoisyEndpointPx = 0.5;   // endpoint noise across the segment (detected lines)
constexpr double kWrongPeakDeg = 5.0;      // beyond this the vote chose another peak
constexpr double kMinHorizontalPx = 40.0;  // a horizontal edge image counted as visible
constexpr int kViews = 60;

// Smallest angular distance (degrees) from `truth` to a candidate heading.
double CandidateErrorDeg(const std::vector<double>& candidates, double truth) {
  double best = 360.0;
  for (double h : candidates)
    best = std::min(best, std::abs(RadToDeg(WrapAngle(h - truth))));
  return best;
}

// Pieces of horizontal edges at least kMinHorizontalPx long whose bearing is certain enough to
// vote (not along the horizon), per model direction (0: along x).
int MaxHorizontalPiecesOfOneDirection(const WireframeModel& model, const CameraIntrinsics& camera,
                                      const RobotPose& pose,
                                      const std::vector<ProjectedEdge>& pieces) {
  int along[2] = {0, 0};
  const HeadingOptions options;
  for (const ProjectedEdge& p : pieces) {
    const ModelEdge& e = model.edges()[p.edge_id];
    if (e.vertical || p.image.Length() < kMinHorizontalPx) continue;
    const VoteLine line = PrepareVoteLines({p.image}, camera, options).front();
    if (BearingAt(line, pose.tilt).sigma > DegToRad(options.max_bearing_sigma_deg)) continue;
    const Eigen::Vector3d d = e.segment.Direction();
    ++along[std::abs(d.x()) > std::abs(d.y()) ? 0 : 1];
  }
  return std::max(along[0], along[1]);
}

std::vector<Segment2> Images(const std::vector<ProjectedEdge>& pieces) {
  std::vector<Segment2> out;
  for (const ProjectedEdge& p : pieces)
    out.push_back(p.image);
  return out;
}

class HeadingEstimatorTest : public ::testing::Test {
 protected:
  testing::HallFixture hall_;
  ModelDirections directions_ = DominantDirections(hall_.model());
};

TEST_F(HeadingEstimatorTest, ExactViewsGiveTheHeadingWithKnownTilt) {
  std::mt19937_64 rng(21);
  int tested = 0;
  for (int n = 0; n < kViews; ++n) {
    const testing::ExactView view = hall_.RandomView(rng);
    if (MaxHorizontalPiecesOfOneDirection(hall_.model(), hall_.camera(), view.pose, view.pieces) <
        2)
      continue;
    ++tested;
    const HeadingCandidates result =
        EstimateHeading(Images(view.pieces), hall_.camera(), view.pose.tilt, directions_);
    ASSERT_TRUE(result.found) << result.reason;
    // Four candidates (the hall's quarter turns), one of them the truth.
    EXPECT_EQ(result.hypotheses.front().headings.size(), 4u);
    EXPECT_LT(CandidateErrorDeg(result.hypotheses.front().headings, view.pose.heading),
              kExactHeadingTolDeg);
    EXPECT_EQ(result.tilt, view.pose.tilt);
    EXPECT_FALSE(result.tilt_estimated);
  }
  EXPECT_GT(tested, kViews / 2);
}

TEST_F(HeadingEstimatorTest, ExactViewsGiveHeadingAndTiltWithUnknownTilt) {
  std::mt19937_64 rng(22);
  int tested = 0;
  for (int n = 0; n < kViews; ++n) {
    const testing::ExactView view = hall_.RandomView(rng);
    if (MaxHorizontalPiecesOfOneDirection(hall_.model(), hall_.camera(), view.pose, view.pieces) <
        2)
      continue;
    const HeadingCandidates result =
        EstimateHeading(Images(view.pieces), hall_.camera(), std::nullopt, directions_);
    if (!result.found) continue;  // too few segments to fix the tilt: counted below
    ++tested;
    EXPECT_TRUE(result.tilt_estimated);
    EXPECT_NEAR(RadToDeg(result.tilt), RadToDeg(view.pose.tilt), kExactTiltTolDeg);
    EXPECT_LT(CandidateErrorDeg(result.BestHeadings(), view.pose.heading), kExactHeadingTolDeg);
  }
  EXPECT_GT(tested, kViews / 2);
}

// Heading errors (degrees) on views of exact pieces whose endpoints move by N(0, sigma_px)
// across the segment (the estimator's noise model), with `clutter_ratio` x as many random
// segments; only views with two pieces of one direction able to vote count.
std::vector<double> NoisyErrors(const testing::HallFixture& hall, const ModelDirections& dirs,
                                double sigma_px, double clutter_ratio, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 640.0), v(0.0, 480.0), angle(-kPi, kPi),
      length(20.0, 200.0);
  std::normal_distribution<double> across(0.0, sigma_px);
  std::vector<double> errors;
  for (int n = 0; n < 3 * kViews; ++n) {
    const testing::ExactView view = hall.RandomView(rng);
    std::vector<Segment2> lines;
    for (const ProjectedEdge& p : view.pieces) {
      const Eigen::Vector2d d = (p.image.b - p.image.a).normalized(), normal(-d.y(), d.x());
      lines.push_back({p.image.a + across(rng) * normal, p.image.b + across(rng) * normal});
    }
    const size_t clutter = static_cast<size_t>(clutter_ratio * lines.size());
    for (size_t c = 0; c < clutter; ++c) {
      const Eigen::Vector2d mid(u(rng), v(rng));
      const double a = angle(rng), l = length(rng);
      const Eigen::Vector2d dir(std::cos(a), std::sin(a));
      lines.push_back({mid - 0.5 * l * dir, mid + 0.5 * l * dir});
    }
    if (MaxHorizontalPiecesOfOneDirection(hall.model(), hall.camera(), view.pose, view.pieces) <
        2) {
      continue;
    }
    const HeadingCandidates result = EstimateHeading(lines, hall.camera(), view.pose.tilt, dirs);
    errors.push_back(result.found ? CandidateErrorDeg(result.BestHeadings(), view.pose.heading)
                                  : 180.0);
  }
  return errors;
}

double ShareWithin(const std::vector<double>& errors, double tolerance) {
  return static_cast<double>(std::count_if(errors.begin(), errors.end(),
                                           [&](double e) { return e <= tolerance; })) /
         errors.size();
}

double MedianOf(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

TEST_F(HeadingEstimatorTest, NoisySegmentsMeetTheAccuracyTargets) {
  const std::vector<double> errors = NoisyErrors(hall_, directions_, kNoisyEndpointPx, 0.0, 23);
  ASSERT_GT(errors.size(), static_cast<size_t>(kViews));
  EXPECT_GE(ShareWithin(errors, kNoisyHeadingTolDeg), 0.9);
  EXPECT_LE(MedianOf(errors), kNoisyMedianTolDeg);
}

TEST_F(HeadingEstimatorTest, RandomClutterSegmentsCostLittleAccuracy) {
  // Half as many random segments as model segments: a precise one near the horizon can pull a
  // heading that only uncertain segments support (docs/heading.md, section 3).
  const std::vector<double> errors = NoisyErrors(hall_, directions_, kNoisyEndpointPx, 0.5, 24);
  ASSERT_GT(errors.size(), static_cast<size_t>(kViews));
  EXPECT_GE(ShareWithin(errors, kNoisyHeadingTolDeg), 0.8);
  EXPECT_LE(MedianOf(errors), kNoisyMedianTolDeg);
  EXPECT_GE(ShareWithin(errors, kWrongPeakDeg), 0.95);
}

// A room whose walls run at 0 and 60 degrees (a parallelogram, no quarter-turn symmetry), with
// rails along the walls at 1 and 2 m.
WireframeModel ParallelogramRoom() {
  const Eigen::Vector2d corners[4] = {{0.0, 0.0},
                                      {10.0, 0.0},
                                      {10.0 + 6.0 * std::cos(kPi / 3.0), 6.0 * std::sin(kPi / 3.0)},
                                      {6.0 * std::cos(kPi / 3.0), 6.0 * std::sin(kPi / 3.0)}};
  CaoModel cao;
  cao.files = {"parallelogram.cao"};
  for (double z : {0.0, 1.0, 2.0, 3.0}) {
    for (const Eigen::Vector2d& c : corners)
      cao.points.emplace_back(c.x(), c.y(), z);
  }
  for (int level = 0; level < 4; ++level) {
    for (int k = 0; k < 4; ++k)
      cao.lines.push_back({4 * level + k, 4 * level + (k + 1) % 4});
  }
  for (int k = 0; k < 4; ++k)
    cao.lines.push_back({k, 12 + k});
  for (int k = 0; k < 4; ++k)
    cao.faces.push_back({k, (k + 1) % 4, 12 + (k + 1) % 4, 12 + k});
  return WireframeModel::FromCao(cao);
}

TEST(HeadingWithoutSymmetry, CandidatesAreTheHeadingAndItsHalfTurn) {
  const WireframeModel room = ParallelogramRoom();
  const ModelDirections directions = DominantDirections(room);
  ASSERT_EQ(directions.angles.size(), 2u);
  EXPECT_NEAR(RadToDeg(directions.angles[1]), 60.0, 1e-9);
  const OcclusionTester occlusion(room);
  CameraIntrinsics camera = testing::HallFixture().camera();
  camera.px = camera.py = 400.0;  // wide enough to see two walls
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> ux(2.0, 10.0), uy(1.0, 4.0), uh(-kPi, kPi),
      ut(0.0, DegToRad(10.0));
  int both_seen = 0;
  for (int n = 0; n < 40; ++n) {
    const RobotPose pose{ux(rng), uy(rng), uh(rng), 1.4, ut(rng)};
    const std::vector<ProjectedEdge> pieces =
        ProjectVisibleEdges(room, occlusion, CamFromWorld(pose), camera);
    const HeadingCandidates result = EstimateHeading(Images(pieces), camera, pose.tilt, directions);
    if (!result.found) continue;
    const int horizontal_points = static_cast<int>(
        std::count_if(result.vanishing_points.begin(), result.vanishing_points.end(),
                      [](const VanishingPoint& vp) { return !vp.vertical; }));
    EXPECT_LT(CandidateErrorDeg(result.BestHeadings(), pose.heading), kExactHeadingTolDeg);
    if (horizontal_points == 2) {
      // Both directions seen: only the half turn remains.
      ++both_seen;
      EXPECT_EQ(result.BestHeadings().size(), 2u);
    } else {
      // One direction: it may be either of the two, each with its half turn.
      EXPECT_EQ(result.BestHeadings().size(), 4u);
    }
  }
  EXPECT_GT(both_seen, 5);
}

TEST_F(HeadingEstimatorTest, VerticalLinesAloneGiveNoHeading) {
  std::mt19937_64 rng(41);
  const testing::ExactView view = hall_.RandomView(rng);
  std::vector<Segment2> verticals;
  for (const ProjectedEdge& p : view.pieces) {
    if (hall_.model().edges()[p.edge_id].vertical) verticals.push_back(p.image);
  }
  const HeadingCandidates result =
      EstimateHeading(verticals, hall_.camera(), view.pose.tilt, directions_);
  EXPECT_FALSE(result.found);
  EXPECT_FALSE(result.reason.empty());
}

TEST_F(HeadingEstimatorTest, BadInputThrows) {
  const std::vector<Segment2> nan_line = {{{0.0, 0.0}, {std::nan(""), 5.0}}};
  EXPECT_THROW(EstimateHeading(nan_line, hall_.camera(), 0.0, directions_), InputError);
  EXPECT_THROW(EstimateHeading({}, hall_.camera(), 0.0, ModelDirections()), InputError);
  HeadingOptions bad;
  bad.min_support = 0;
  std::string why;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_THROW(EstimateHeading({}, hall_.camera(), 0.0, directions_, bad), InputError);
}

TEST(HeadingAccumulator, PeakIsTheBestBinAndSuppressionClearsAroundIt) {
  HeadingAccumulator acc;
  acc.bin_width = DegToRad(1.0);
  acc.scores.assign(180, 0.0);
  acc.scores[10] = 2.5;
  acc.scores[11] = 3.0;
  acc.scores[179] = 2.0;
  EXPECT_EQ(acc.Max(), 3.0);
  EXPECT_NEAR(RadToDeg(acc.Peak()), 11.5, 1e-9);
  acc.Suppress(DegToRad(11.0), DegToRad(2.0));
  EXPECT_EQ(acc.Max(), 2.0);
  acc.Suppress(DegToRad(0.5), DegToRad(1.0));  // wraps past 0
  EXPECT_EQ(acc.Max(), 0.0);
}

TEST(HeadingAccumulator, ASegmentVotesOnceWithTheNearestDirectionsKernel) {
  // A segment straight ahead in a level camera votes for every model direction's heading.
  const CameraIntrinsics camera = testing::HallFixture().camera();
  HeadingOptions options;
  const std::vector<VoteLine> lines =
      PrepareVoteLines({{{100.0, 300.0}, {540.0, 300.0}}}, camera, options);
  ASSERT_EQ(lines.size(), 1u);
  const ModelDirections dirs = DirectionsFromAngles({0.0, DegToRad(2.5)}, DegToRad(0.1));
  const HeadingAccumulator acc = VoteHeadings(lines, {false}, 0.0, dirs, options);
  const double sigma =
      std::max(BearingAt(lines.front(), 0.0).sigma, DegToRad(options.min_bearing_sigma_deg));
  // The peak is one kernel's, not the sum of the two directions' overlapping kernels.
  EXPECT_NEAR(acc.Max(), InlierLogRatio(0.0, sigma, kPi, options.outlier_probability), 1e-3);
}

}  // namespace
}  // namespace linetrack
