// The integrity monitor (tracking/integrity/integrity_monitor.h) on exact synthetic scenes: the
// solution separation finds and excludes an edge latched onto a parallel line, the protection
// levels bound the error when a smaller fault goes undetected, and the covariance grows as the
// edges become fewer, shorter or more parallel.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "tests/tracking/integrity_scene.h"
#include "tracking/integrity/consistency.h"
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

constexpr double kLatchPx = 3.0;
constexpr int kSeeds = 8;
constexpr double kMinDetectedShare = 0.8;
const std::vector<int> kFloorLines = {0, 9};  // RoomEdges(): the floor lines along the room

IntegrityOptions OptionsFor(const SceneNoise& noise) {
  IntegrityOptions options;
  options.solver = SolverOptionsFor(noise);
  return options;
}

// Position (metres) and heading (radians) errors of a robot estimate.
Eigen::Vector2d RobotErrors(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  const Eigen::VectorXd e = RobotParameters().Difference(estimate, truth);
  return {e.head<2>().norm(), std::abs(e[2])};
}

TEST(IntegrityMonitor, OptionsCheck) {
  std::string why;
  EXPECT_TRUE(IntegrityOptions().Check(&why)) << why;
  IntegrityOptions bad;
  bad.integrity_risk = 0.0;
  EXPECT_FALSE(bad.Check(&why));
  bad = IntegrityOptions();
  bad.solver.noise.latch_sigma_px = -0.1;
  EXPECT_FALSE(bad.Check(&why));
  bad = IntegrityOptions();
  bad.alert_rotation_rad = 0.0;
  EXPECT_FALSE(bad.Check(&why));
}

// Without faults the pose is tracking, its protection levels bound its error and lie within
// the alert limits; with alert limits below them it is degraded, with the reason.
TEST(IntegrityMonitor, FaultFreePoseIsTrackingAndDegradedBelowItsProtectionLevel) {
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Isometry3d truth = CamFromWorld(TestRobotPose());
  std::mt19937 random(5);
  const std::vector<EdgeObservation> observations =
      Observe(RoomEdges(), camera, truth, RealisticNoise(), &random);
  IntegrityOptions options = OptionsFor(RealisticNoise());
  const PoseIntegrity p =
      EvaluatePoseIntegrity(observations, camera, Start(truth), RobotParameters(), options);
  EXPECT_EQ(p.status, IntegrityStatus::kTracking) << p.reason;
  EXPECT_TRUE(p.excluded.empty()) << p.reason;
  const Eigen::Vector2d errors = RobotErrors(p.solution.cam_from_world, truth);
  EXPECT_LE(errors[0], p.levels.position_m);
  EXPECT_LE(errors[1], p.levels.rotation_rad);
  EXPECT_GE(p.levels.position_m, p.levels.fault_free_position_m);
  options.alert_position_m = 0.5 * p.levels.position_m;
  const PoseIntegrity tight =
      EvaluatePoseIntegrity(observations, camera, Start(truth), RobotParameters(), options);
  EXPECT_EQ(tight.status, IntegrityStatus::kDegraded);
  EXPECT_NE(tight.reason.find("position protection"), std::string::npos) << tight.reason;
}

// Every edge in turn latched 3 px onto a parallel line: the separation test finds most of them
// and excludes them (never another edge), always those of the long floor lines; whether found or
// not, the pose is within its protection levels. A fault is found when it exceeds what the
// edge's own error model (about 0.7 px here: 5 mm at 4 m and a 0.3 px latch) and the pose's
// leeway can absorb: 3 px on a door's vertical beside the image border is not.
TEST(IntegrityMonitor, ExcludesAnEdgeLatchedThreePixelsOntoAParallelLine) {
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Isometry3d truth = CamFromWorld(TestRobotPose());
  const std::vector<Segment3> edges = RoomEdges();
  const IntegrityOptions options = OptionsFor(RealisticNoise());
  int cases = 0, excluded_right = 0, excluded_wrong = 0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    for (size_t k = 0; k < edges.size(); ++k) {
      std::vector<double> shift(edges.size(), 0.0);
      shift[k] = kLatchPx;
      std::mt19937 random(100 + seed);
      const std::vector<EdgeObservation> observations =
          Observe(edges, camera, truth, RealisticNoise(), &random, shift);
      auto it = std::find_if(observations.begin(), observations.end(),
                             [&](const EdgeObservation& o) { return o.model_edge == int(k); });
      if (it == observations.end()) continue;
      ++cases;
      const PoseIntegrity p =
          EvaluatePoseIntegrity(observations, camera, Start(truth), RobotParameters(), options);
      ASSERT_NE(p.status, IntegrityStatus::kLost) << "edge " << k << ": " << p.reason;
      const int index = static_cast<int>(it - observations.begin());
      const bool found = std::count(p.excluded.begin(), p.excluded.end(), index) > 0;
      excluded_right += found;
      excluded_wrong += static_cast<int>(p.excluded.size()) - found;
      if (std::count(kFloorLines.begin(), kFloorLines.end(), static_cast<int>(k))) {
        EXPECT_TRUE(found) << "edge " << k << ", seed " << seed << ": " << p.reason;
      }
      const Eigen::Vector2d errors = RobotErrors(p.solution.cam_from_world, truth);
      EXPECT_LE(errors[0], p.levels.position_m) << "edge " << k << ": " << p.reason;
      EXPECT_LE(errors[1], p.levels.rotation_rad) << "edge " << k << ": " << p.reason;
    }
  }
  std::cout << "latched edges excluded: " << excluded_right << " of " << cases << ", others "
            << excluded_wrong << "\n";
  EXPECT_GE(excluded_right, kMinDetectedShare * cases);
  EXPECT_EQ(excluded_wrong, 0);
}

// A free camera (6 unknowns): a floor line latched 3 px is excluded, and the pose is tracking
// within its protection levels (camera centre, rotation angle).
TEST(IntegrityMonitor, FreeCameraExcludesALatchedFloorLine) {
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Isometry3d truth = CamFromWorld(TestRobotPose());
  const std::vector<Segment3> edges = RoomEdges();
  for (int seed = 0; seed < kSeeds; ++seed) {
    std::vector<double> shift(edges.size(), 0.0);
    shift[kFloorLines[0]] = kLatchPx;
    std::mt19937 random(300 + seed);
    const std::vector<EdgeObservation> observations =
        Observe(edges, camera, truth, RealisticNoise(), &random, shift);
    const PoseIntegrity p = EvaluatePoseIntegrity(
        observations, camera, Start(truth), PoseParameterisation(), OptionsFor(RealisticNoise()));
    EXPECT_EQ(p.status, IntegrityStatus::kTracking) << p.reason;
    ASSERT_EQ(p.excluded.size(), 1u) << p.reason;
    EXPECT_EQ(observations[p.excluded[0]].model_edge, kFloorLines[0]);
    const WorldTwist e = WorldTwistBetween(truth, p.solution.cam_from_world);
    EXPECT_LE(e.head<3>().norm(), p.levels.position_m);
    EXPECT_LE(e.tail<3>().norm(), p.levels.rotation_rad);
  }
}

// Faults of 0.5 to 2.5 px on one edge, detected or not: no pose that is not lost has an error
// beyond its protection levels (an integrity failure); the covariance averaged over the fault
// hypotheses holds more truths in its 99.9 % region than the fault-free one, and when the fault
// stays in, the faulty edge is the most probable culprit more often than any other.
TEST(IntegrityMonitor, ProtectionLevelsBoundTheErrorOfUndetectedFaults) {
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Isometry3d truth = CamFromWorld(TestRobotPose());
  const std::vector<Segment3> edges = RoomEdges();
  const IntegrityOptions options = OptionsFor(RealisticNoise());
  const double region = ChiSquareUpperQuantile(3, 0.001);
  int poses = 0, failures = 0, excluded = 0, outside_fault_free = 0, outside_fault_aware = 0;
  int kept = 0, culprit_first = 0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    for (double latch : {0.5, 1.0, 1.5, 2.0, 2.5}) {
      for (size_t k = 0; k < edges.size(); ++k) {
        std::vector<double> shift(edges.size(), 0.0);
        shift[k] = latch;
        std::mt19937 random(200 + seed);
        const std::vector<EdgeObservation> observations =
            Observe(edges, camera, truth, RealisticNoise(), &random, shift);
        const PoseIntegrity p =
            EvaluatePoseIntegrity(observations, camera, Start(truth), RobotParameters(), options);
        if (p.status == IntegrityStatus::kLost) continue;
        ++poses;
        excluded += !p.excluded.empty();
        const Eigen::VectorXd e = RobotParameters().Difference(p.solution.cam_from_world, truth);
        failures +=
            e.head<2>().norm() > p.levels.position_m || std::abs(e[2]) > p.levels.rotation_rad;
        outside_fault_free += Nees(e, p.solution.covariance) > region;
        outside_fault_aware += Nees(e, p.covariance) > region;
        if (!p.excluded.empty() || latch < 1.5) continue;
        std::vector<EdgeSeparation> separations = SolutionSeparations(p.solution, options);
        FaultProbabilities(p.solution, options, &separations);
        const auto most = std::max_element(separations.begin(), separations.end(),
                                           [](const EdgeSeparation& a, const EdgeSeparation& b) {
                                             return a.probability_faulty < b.probability_faulty;
                                           });
        ++kept;
        culprit_first += observations[most->observation].model_edge == static_cast<int>(k);
      }
    }
  }
  std::cout << "poses " << poses << ", with an exclusion " << excluded << ", integrity failures "
            << failures << "; outside the 99.9 % region: fault-free covariance "
            << outside_fault_free << ", fault-aware " << outside_fault_aware
            << "; faults of 1.5 px or more kept: " << kept << ", culprit most probable "
            << culprit_first << "\n";
  EXPECT_GT(poses, 0);
  EXPECT_EQ(failures, 0);
  EXPECT_LT(outside_fault_aware, outside_fault_free);
  EXPECT_GT(culprit_first, kept / 2);
}

// The observations of the room's edges along x (floor and ceiling lines) only.
std::vector<EdgeObservation> LinesAlongTheRoom(const CameraIntrinsics& camera,
                                               const Eigen::Isometry3d& truth) {
  std::mt19937 random(2);
  std::vector<EdgeObservation> parallel;
  for (const EdgeObservation& o : Observe(RoomEdges(), camera, truth, RealisticNoise(), &random)) {
    if (std::abs((o.b - o.a).normalized().x()) > 0.99) parallel.push_back(o);
  }
  return parallel;
}

// A prior (the odometry's prediction) fixes what the edges leave free.
TEST(IntegrityMonitor, APriorFixesWhatTheEdgesLeaveFree) {
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Isometry3d truth = CamFromWorld(TestRobotPose());
  const std::vector<EdgeObservation> parallel = LinesAlongTheRoom(camera, truth);
  PosePrior prior;
  prior.cam_from_world = truth;
  prior.covariance =
      Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, DegToRad(1.0) * DegToRad(1.0)).asDiagonal();
  const EdgePoseSolution s = SolveEdgePose(parallel, camera, Start(truth), RobotParameters(),
                                           SolverOptionsFor(RealisticNoise()), {}, prior);
  ASSERT_TRUE(s.ok) << s.reason;
  // x along the lines: the prior's alone; y and heading: the edges', far below the prior's.
  EXPECT_NEAR(std::sqrt(s.covariance(0, 0)), 0.05, 0.005);
  EXPECT_LT(std::sqrt(s.covariance(1, 1)), 0.01);
  EXPECT_LT(std::sqrt(s.covariance(2, 2)), DegToRad(0.1));
}

// Largest position and heading sigmas of the robot pose from `observations`.
Eigen::Vector2d Sigmas(const std::vector<EdgeObservation>& observations) {
  const EdgePoseSolution s =
      SolveEdgePose(observations, TestCamera(), CamFromWorld(TestRobotPose()), RobotParameters(),
                    SolverOptionsFor(RealisticNoise()));
  EXPECT_TRUE(s.ok) << s.reason;
  return LargestSigmas(RobotParameters(), s.covariance);
}

TEST(IntegrityMonitor, CovarianceGrowsAsEdgesBecomeFewerShorterOrParallel) {
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Isometry3d truth = CamFromWorld(TestRobotPose());
  SceneNoise exact = RealisticNoise();
  exact.point_px = 0.0;
  exact.model_m = 0.0;
  exact.latch_px = 0.0;
  std::mt19937 random(1);
  const std::vector<EdgeObservation> all = Observe(RoomEdges(), camera, truth, exact, &random);
  const Eigen::Vector2d base = Sigmas(all);
  // Fewer: every other edge.
  std::vector<EdgeObservation> fewer;
  for (size_t k = 0; k < all.size(); k += 2)
    fewer.push_back(all[k]);
  const Eigen::Vector2d few = Sigmas(fewer);
  EXPECT_GT(few[0], base[0]);
  EXPECT_GT(few[1], base[1]);
  // Shorter: the middle third of each edge's points.
  std::vector<EdgeObservation> shorter = all;
  for (EdgeObservation& o : shorter) {
    const size_t n = o.points.size();
    o.points = std::vector<Eigen::Vector2d>(o.points.begin() + n / 3, o.points.begin() + n - n / 3);
  }
  const Eigen::Vector2d short_sigmas = Sigmas(shorter);
  EXPECT_GT(short_sigmas[0], base[0]);
  EXPECT_GT(short_sigmas[1], base[1]);
  // More parallel: the lines along the room (floor and ceiling) and one vertical only.
  std::vector<EdgeObservation> parallel;
  for (const EdgeObservation& o : all) {
    const Eigen::Vector3d d = (o.b - o.a).normalized();
    if (std::abs(d.x()) > 0.99) parallel.push_back(o);
  }
  ASSERT_GE(parallel.size(), 3u);
  parallel.push_back(*std::find_if(all.begin(), all.end(), [](const EdgeObservation& o) {
    return std::abs((o.b - o.a).normalized().z()) > 0.99;
  }));
  const Eigen::Vector2d parallel_sigmas = Sigmas(parallel);
  EXPECT_GT(parallel_sigmas[0], 3.0 * base[0]);
}

// Lines along one direction only leave the position along them free: no pose, and the reason.
TEST(IntegrityMonitor, ParallelLinesAloneAreLost) {
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Isometry3d truth = CamFromWorld(TestRobotPose());
  const std::vector<EdgeObservation> parallel = LinesAlongTheRoom(camera, truth);
  ASSERT_GE(parallel.size(), 3u);
  const PoseIntegrity p = EvaluatePoseIntegrity(parallel, camera, Start(truth), RobotParameters(),
                                                OptionsFor(RealisticNoise()));
  EXPECT_EQ(p.status, IntegrityStatus::kLost);
  EXPECT_NE(p.reason.find("do not fix"), std::string::npos) << p.reason;
}

}  // namespace
}  // namespace linetrack
