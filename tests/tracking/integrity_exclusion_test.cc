// Protection levels after an exclusion (ExclusionProtectionLevels, docs/integrity.md section 2.3)
// on exact synthetic scenes: Monte Carlos with a known faulty edge (or none, with frequent false
// alarms) and with two faulty edges that agree (a door jamb of each of two doors latched the same
// way), in which the levels bound the error at the stated rate; a clear fault is excluded and
// every other single-fault hypothesis refuted; without an exclusion the levels are the
// detection-only ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <iostream>
#include <random>

#include "tests/tracking/integrity_scene.h"
#include "tracking/integrity/integrity_monitor.h"

namespace linetrack {
namespace {

using integrity_test::Observe;
using integrity_test::RealisticNoise;
using integrity_test::RobotParameters;
using integrity_test::RoomEdges;
using integrity_test::SceneNoise;
using integrity_test::SolverOptionsFor;
using integrity_test::Start;
using integrity_test::TestCamera;
using integrity_test::TestRobotPose;

constexpr int kDraws = 600;
// Faults drawn on the chosen edge (pixels at both ends): none, marginal, clear.
const std::vector<double> kFaultsPx = {0.0, 1.5, 2.5, 4.0};
// A false alarm on one pose in 20, so that exclusions of fault-free edges are common.
constexpr double kFalseAlarm = 0.05;
constexpr int kFloorLine = 0;  // RoomEdges(): a floor line along the room
// RoomEdges(): a jamb of each door on one side wall, the same side of both doors.
const std::vector<std::array<int, 2>> kSameSideJambs = {{3, 6}, {4, 7}, {12, 15}, {13, 16}};
const std::vector<double> kPairFaultsPx = {2.0, 3.0, 4.0, 5.0};
constexpr double kSolveTolerance = 1e-6;  // metres, radians: the Gauss-Newton solve stops below

IntegrityOptions MonteCarloOptions() {
  IntegrityOptions options;
  options.solver = SolverOptionsFor(RealisticNoise());
  options.false_alarm_probability = kFalseAlarm;
  return options;
}

// True when the robot pose's error is beyond either level.
bool Fails(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth,
           const ProtectionLevels& levels) {
  const Eigen::VectorXd e = RobotParameters().Difference(estimate, truth);
  return e.head<2>().norm() > levels.position_m || std::abs(e[2]) > levels.rotation_rad;
}

// Upper end of the failures allowed in `n` poses at the stated risk: its mean plus three of
// its binomial standard deviations, at least one.
double AllowedFailures(double risk, int n) {
  return std::max(1.0, risk * n + 3.0 * std::sqrt(risk * n));
}

struct Tally {
  int poses = 0, tracking = 0, with_exclusion = 0, failures = 0, subset_failures = 0;
};

// Runs kDraws seeded rooms, draw d with the faults shift_of(d) (pixels per edge), and counts the
// poses, their exclusions and integrity failures; the levels after an exclusion are never below
// the subset's own (the excluded edges left out, as if never seen), whose failures are counted.
Tally RunDraws(const std::function<std::vector<double>(int)>& shift_of, unsigned seed_base) {
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Isometry3d truth = CamFromWorld(TestRobotPose());
  const std::vector<Segment3> edges = RoomEdges();
  const IntegrityOptions options = MonteCarloOptions();
  Tally t;
  for (int draw = 0; draw < kDraws; ++draw) {
    std::mt19937 random(seed_base + draw);
    const std::vector<EdgeObservation> observations =
        Observe(edges, camera, truth, RealisticNoise(), &random, shift_of(draw));
    const PoseIntegrity p =
        EvaluatePoseIntegrity(observations, camera, Start(truth), RobotParameters(), options);
    if (p.status == IntegrityStatus::kLost) continue;
    ++t.poses;
    t.tracking += p.status == IntegrityStatus::kTracking;
    t.failures += Fails(p.solution.cam_from_world, truth, p.levels);
    if (p.excluded.empty()) {
      EXPECT_EQ(p.levels.unrefuted_hypotheses, 0);
      continue;
    }
    ++t.with_exclusion;
    const ProtectionLevels subset =
        ComputeProtectionLevels(p.solution, SolutionSeparations(p.solution, options), options);
    EXPECT_GE(p.levels.position_m, subset.position_m);
    EXPECT_GE(p.levels.rotation_rad, subset.rotation_rad);
    t.subset_failures += Fails(p.solution.cam_from_world, truth, subset);
  }
  return t;
}

// The risk the levels after an exclusion are stated at: the integrity risk plus twice the
// exclusion risk per pose.
double StatedRisk() {
  const IntegrityOptions options = MonteCarloOptions();
  return options.integrity_risk + 2.0 * options.exclusion_risk;
}

// Each draw: a seeded room, one edge in turn with one of kFaultsPx. The levels after an
// exclusion hold the truth at the stated rate.
TEST(IntegrityExclusion, LevelsAfterAnExclusionBoundTheErrorAtTheStatedRate) {
  const size_t edges = RoomEdges().size();
  const Tally t = RunDraws(
      [&](int draw) {
        std::vector<double> shift(edges, 0.0);
        shift[draw % edges] = kFaultsPx[(draw / edges) % kFaultsPx.size()];
        return shift;
      },
      1000);
  std::cout << "one fault: poses " << t.poses << " (tracking " << t.tracking
            << "), with an exclusion " << t.with_exclusion << "; integrity failures " << t.failures
            << ", with the subset's own levels " << t.subset_failures << " (allowed "
            << AllowedFailures(StatedRisk(), t.poses) << ")\n";
  ASSERT_GT(t.with_exclusion, t.poses / 10);
  EXPECT_LE(t.failures, AllowedFailures(StatedRisk(), t.poses));
}

// Two jambs of the same side of two doors latched the same way (onto their casings): agreeing
// faults that no single edge's separation shows. After an exclusion the levels, which cover two
// more faulty edges, hold the truth at the stated rate (the subset's own levels are printed).
TEST(IntegrityExclusion, LevelsAfterAnExclusionBoundTwoAgreeingFaults) {
  const size_t edges = RoomEdges().size();
  const Tally t = RunDraws(
      [&](int draw) {
        const std::array<int, 2>& pair = kSameSideJambs[draw % kSameSideJambs.size()];
        std::vector<double> shift(edges, 0.0);
        shift[pair[0]] = shift[pair[1]] =
            kPairFaultsPx[(draw / kSameSideJambs.size()) % kPairFaultsPx.size()];
        return shift;
      },
      7000);
  std::cout << "two agreeing faults: poses " << t.poses << ", with an exclusion "
            << t.with_exclusion << "; integrity failures " << t.failures
            << ", with the subset's own levels " << t.subset_failures << " (allowed "
            << AllowedFailures(StatedRisk(), t.poses) << ")\n";
  ASSERT_GT(t.with_exclusion, t.poses / 10);
  EXPECT_LE(t.failures, AllowedFailures(StatedRisk(), t.poses));
}

// A floor line latched 4 px is excluded; every hypothesis that the exclusion was wrong is refuted
// by the data (only the excluded edge's own stays), and the pose is within its levels.
TEST(IntegrityExclusion, AClearFaultIsExcludedAndTheOtherHypothesesRefuted) {
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Isometry3d truth = CamFromWorld(TestRobotPose());
  const std::vector<Segment3> edges = RoomEdges();
  IntegrityOptions options = MonteCarloOptions();
  options.false_alarm_probability = IntegrityOptions().false_alarm_probability;
  for (int seed = 0; seed < 8; ++seed) {
    std::vector<double> shift(edges.size(), 0.0);
    shift[kFloorLine] = 4.0;
    std::mt19937 random(300 + seed);
    const std::vector<EdgeObservation> observations =
        Observe(edges, camera, truth, RealisticNoise(), &random, shift);
    const PoseIntegrity p =
        EvaluatePoseIntegrity(observations, camera, Start(truth), RobotParameters(), options);
    ASSERT_EQ(p.excluded.size(), 1u) << p.reason;
    EXPECT_EQ(observations[p.excluded[0]].model_edge, kFloorLine);
    EXPECT_EQ(p.levels.unrefuted_hypotheses, 1) << "seed " << seed;
    EXPECT_NE(p.status, IntegrityStatus::kLost) << p.reason;
    EXPECT_FALSE(Fails(p.solution.cam_from_world, truth, p.levels));
  }
}

// Without an exclusion the levels are the detection-only ones.
TEST(IntegrityExclusion, NoExclusionLeavesTheLevelsUnchanged) {
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Isometry3d truth = CamFromWorld(TestRobotPose());
  std::mt19937 random(7);
  const std::vector<EdgeObservation> observations =
      Observe(RoomEdges(), camera, truth, RealisticNoise(), &random);
  const IntegrityOptions options = MonteCarloOptions();
  const EdgePoseSolution solution =
      SolveEdgePose(observations, camera, Start(truth), RobotParameters(), options.solver);
  ASSERT_TRUE(solution.ok) << solution.reason;
  const std::vector<EdgeSeparation> separations = SolutionSeparations(solution, options);
  const ProtectionLevels levels = ComputeProtectionLevels(solution, separations, options);
  const ProtectionLevels same =
      ExclusionProtectionLevels(solution, separations, solution, {}, levels, options);
  EXPECT_EQ(same.position_m, levels.position_m);
  EXPECT_EQ(same.rotation_rad, levels.rotation_rad);
  EXPECT_EQ(same.unrefuted_hypotheses, 0);
  // The same solution called the result of an exclusion: no test fails, so no hypothesis is
  // refuted, and with x = x_0 their levels are the detection-only levels' own terms.
  const ProtectionLevels widened =
      ExclusionProtectionLevels(solution, separations, solution, {-1}, levels, options);
  EXPECT_EQ(widened.unrefuted_hypotheses, static_cast<int>(solution.edges.size()) + 1);
  EXPECT_NEAR(widened.wrong_exclusion_position_m, levels.position_m, kSolveTolerance);
  EXPECT_NEAR(widened.wrong_exclusion_rotation_rad, levels.rotation_rad, kSolveTolerance);
}

}  // namespace
}  // namespace linetrack
