// A camera rolled about its optical axis (a mount's roll) on exact views of the hall: its lines
// de-rolled are the lines the unrolled camera sees, and the matcher given the known roll finds the
// exact pose, the roll composed into it; without the roll it does not.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "matching/localizer.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/occlusion.h"
#include "models/robot_pose.h"
#include "models/view_invariant_regions.h"
#include "scene_fixture.h"

namespace linetrack {
namespace {

constexpr double kPixelTol = 1e-9;
constexpr double kPositionTolM = 1e-4;  // exact lines: the refinement's convergence
constexpr double kHeadingTolRad = 1e-5;

TEST(RolledCamera, UnrolledLinesAreTheUnrolledCamerasView) {
  const testing::HallFixture hall;
  const OcclusionTester occlusion(hall.model());
  const RobotPose unrolled{5.0, 3.0, DegToRad(20.0), 1.4, DegToRad(8.0)};
  for (double roll_deg : {3.0, -7.0, 180.0}) {
    RobotPose rolled = unrolled;
    rolled.roll = DegToRad(roll_deg);
    const std::vector<ProjectedEdge> pieces =
        ProjectVisibleEdges(hall.model(), occlusion, CamFromWorld(rolled), hall.camera());
    ASSERT_GE(pieces.size(), 5u);
    std::vector<Segment2> lines;
    for (const ProjectedEdge& piece : pieces)
      lines.push_back(piece.image);
    const std::vector<Segment2> back = UnrolledLines(lines, hall.camera(), rolled.roll);
    const Eigen::Isometry3d level = CamFromWorld(unrolled);
    for (size_t i = 0; i < pieces.size(); ++i) {
      EXPECT_LT((back[i].a - hall.camera().Project(level * pieces[i].world.a)).norm(), kPixelTol);
      EXPECT_LT((back[i].b - hall.camera().Project(level * pieces[i].world.b)).norm(), kPixelTol);
    }
  }
}

TEST(RolledCamera, MatcherFindsTheExactPoseWithTheKnownRoll) {
  const testing::HallFixture hall;
  const OcclusionTester occlusion(hall.model());
  const ViewInvariantRegions regions = ViewInvariantRegions::Build(hall.model(), hall.area());
  const Localizer localizer(hall.model(), &regions, &hall.area(), hall.camera());
  std::mt19937_64 rng(16);
  for (double roll_deg : {0.87, -3.0, 180.0}) {
    const testing::ExactView view = hall.RandomView(rng, 10, 30.0);
    RobotPose truth = view.pose;
    truth.roll = DegToRad(roll_deg);
    EdgeProjectionOptions projection;
    projection.min_length_px = 30.0;
    const std::vector<ProjectedEdge> pieces = ProjectVisibleEdges(
        hall.model(), occlusion, CamFromWorld(truth), hall.camera(), projection);
    LocalizationProblem problem;
    for (const ProjectedEdge& piece : pieces)
      problem.lines.push_back(piece.image);
    problem.prior = {truth.x + 0.2, truth.y - 0.1, truth.heading + DegToRad(3.0)};
    problem.delta_t = 0.5;
    problem.delta_phi = DegToRad(15.0);
    problem.height = truth.height;
    problem.tilt = truth.tilt;
    problem.roll = truth.roll;
    const LocalizationResult r = localizer.Localize(problem);
    ASSERT_TRUE(r.found) << "roll " << roll_deg << ": " << r.reason;
    EXPECT_LT(std::hypot(r.pose.x - truth.x, r.pose.y - truth.y), kPositionTolM);
    EXPECT_LT(std::abs(WrapAngle(r.pose.heading - truth.heading)), kHeadingTolRad);
    EXPECT_EQ(r.pose.roll, truth.roll);
    EXPECT_NEAR(RollOf(r.cam_from_world), truth.roll, 1e-12);
    EXPECT_TRUE(r.cam_from_world.isApprox(CamFromWorld(r.pose)));
    for (const auto& [edge, line] : r.matches)
      EXPECT_EQ(pieces.at(line).edge_id, edge) << "roll " << roll_deg;

    // The same lines with the camera believed level: no pose, or not the truth.
    problem.roll = 0.0;
    const LocalizationResult level = localizer.Localize(problem);
    if (level.found) {
      EXPECT_GT(std::hypot(level.pose.x - truth.x, level.pose.y - truth.y) +
                    std::abs(WrapAngle(level.pose.heading - truth.heading)),
                10.0 * kPositionTolM)
          << "roll " << roll_deg;
    }
  }
}

TEST(RolledCamera, RollIsCheckedAsInput) {
  LocalizationProblem problem;
  problem.lines.push_back({{0.0, 0.0}, {10.0, 0.0}});
  problem.delta_t = 0.5;
  problem.delta_phi = 0.2;
  problem.height = 1.3;
  problem.roll = std::nan("");
  EXPECT_THROW(CheckProblem(problem), InputError);
  problem.roll = 4.0;
  EXPECT_THROW(CheckProblem(problem), InputError);
  problem.roll = -0.1;
  EXPECT_NO_THROW(CheckProblem(problem));
}

}  // namespace
}  // namespace linetrack
