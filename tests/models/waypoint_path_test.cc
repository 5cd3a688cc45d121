// Waypoint paths: the file format and its errors, rounded corners of the asked radius, the
// heading along the path or as given at a waypoint, closed paths that lap, the constant-rate
// head pan, and the odometry's stated drift measured against the truth.
#include "models/render/waypoint_path.h"

#include <gtest/gtest.h>

#include <cmath>

#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack {
namespace {

constexpr double kTol = 1e-9;
constexpr double kLengthTolM = 0.02;    // resampled path length against the exact one
constexpr double kOnPathTolM = 0.005;   // samples from the exact rounded polyline
constexpr double kHeadingTolDeg = 0.5;  // a waypoint's heading (chord direction over 0.4 m)
constexpr double kMaxDriftRatio = 1.2;  // largest 10 m drift over the stated one
constexpr double kMinDriftRatio = 0.5;  // mean 10 m drift over the stated one

NavigableArea HallArea() {
  NavigableAreaOptions options;
  options.sidecar_path = std::string(LINETRACK_SOURCE_DIR) + "/tests/data/hall.nav.json";
  return NavigableArea::FromModel(
      WireframeModel::Load(std::string(LINETRACK_SOURCE_DIR) + "/models/hall.cao"), options);
}

TEST(Waypoints, ParsesPositionsHeadingsAndComments) {
  const std::vector<Waypoint> w =
      ParseWaypoints("# a path\n1,2\n\n 3.5 , 4 , 90  # facing north\n5,6,-45\n", "p.csv");
  ASSERT_EQ(w.size(), 3u);
  EXPECT_EQ(w[0].position, Eigen::Vector2d(1, 2));
  EXPECT_FALSE(w[0].heading.has_value());
  EXPECT_NEAR(*w[1].heading, kPi / 2, kTol);
  EXPECT_NEAR(*w[2].heading, -kPi / 4, kTol);
}

TEST(Waypoints, BadTextNamesTheLine) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"1,2\n3\n", "p.csv:2:"},
      {"1,2\n3,4,5,6\n", "p.csv:2:"},
      {"1,2\nx,4\n", "p.csv:2: not a number: 'x'"},
      {"1,2\n3,nan\n", "p.csv:2:"},
      {"1,2\n1.001,2\n", "p.csv:2:"},
      {"1,2\n", "at least two"},
      {"1,2\n3,4,\n", "p.csv:2:"},
  };
  for (const auto& [text, what] : cases) {
    try {
      ParseWaypoints(text, "p.csv");
      ADD_FAILURE() << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << text << e.what();
    }
  }
  EXPECT_THROW(ReadWaypoints("/nonexistent/path.csv"), InputError);
}

// An L: 4 m east then 3 m north, the corner rounded with radius r. Its length is
// 4 + 3 - 2 r + r pi / 2 (two tangent lengths of r replaced by a quarter circle).
TEST(WaypointPath, RoundsCornersWithTheAskedRadius) {
  const double r = 0.8;
  WaypointPathOptions options;
  options.corner_radius = r;
  const SampledPath path =
      PathThroughWaypoints(ParseWaypoints("0,0\n4,0\n4,3\n", "l.csv"), options, "l.csv");
  EXPECT_FALSE(path.closed);
  EXPECT_NEAR(path.Length(), 7.0 - 2.0 * r + r * kPi / 2.0, kLengthTolM);
  EXPECT_NEAR(path.step, options.step, 0.01 * options.step);
  const Eigen::Vector2d centre(4.0 - r, r);
  for (const Eigen::Vector2d& p : path.points) {
    double distance = 0.0;  // from the exact rounded L
    if (p.x() <= 4.0 - r) {
      distance = std::abs(p.y());
    } else if (p.y() >= r) {
      distance = std::abs(p.x() - 4.0);
    } else {
      distance = std::abs((p - centre).norm() - r);
    }
    EXPECT_LT(distance, kOnPathTolM) << p.transpose();
  }
  EXPECT_LT((path.points.front() - Eigen::Vector2d(0, 0)).norm(), kTol);
  EXPECT_LT((path.points.back() - Eigen::Vector2d(4, 3)).norm(), 1e-6);
  EXPECT_TRUE(path.heading_knots.empty());
  EXPECT_NEAR(path.DirectionAt(1.0), 0.0, 1e-6);
  EXPECT_NEAR(path.DirectionAt(path.Length() - 1.0), kPi / 2, 1e-6);
}

TEST(WaypointPath, GivenHeadingsHoldAtTheirWaypoints) {
  WaypointPathOptions options;
  const SampledPath path = PathThroughWaypoints(
      ParseWaypoints("0,0\n3,0,-90\n6,0\n6,4,180\n", "h.csv"), options, "h.csv");
  DriveOptions drive;
  drive.speed = 0.5;
  drive.fps = 100.0;  // 5 mm between frames
  const std::vector<SequenceFrame> frames = DriveAlongPath(path, drive);
  double at_second = 1e9, at_last = 1e9;
  for (const SequenceFrame& f : frames) {
    const Eigen::Vector2d p(f.base.x, f.base.y);
    if ((p - Eigen::Vector2d(3, 0)).norm() < 0.003)
      at_second = std::min(at_second, std::abs(WrapAngle(f.base.heading + kPi / 2)));
    if ((p - Eigen::Vector2d(6, 4)).norm() < 0.003)
      at_last = std::min(at_last, std::abs(WrapAngle(f.base.heading - kPi)));
  }
  EXPECT_LT(RadToDeg(at_second), kHeadingTolDeg);
  EXPECT_LT(RadToDeg(at_last), kHeadingTolDeg);
  // Halfway between the first waypoint (heading along the path, 0) and the second (-90): -45.
  EXPECT_NEAR(RadToDeg(WrapAngle(frames[300].base.heading)), -45.0, 1.0);  // at 1.5 m
  // Driving to the end: the last frame is at the end of the path; more frames are refused.
  EXPECT_LT(
      (Eigen::Vector2d(frames.back().base.x, frames.back().base.y) - Eigen::Vector2d(6, 4)).norm(),
      drive.speed / drive.fps + 1e-6);
  drive.frames = static_cast<int>(frames.size()) + 10;
  EXPECT_THROW(DriveAlongPath(path, drive), InputError);
}

TEST(WaypointPath, ClosedPathsLapAndStayInTheHall) {
  const SampledPath path = PathThroughWaypoints(
      ParseWaypoints("1.5,1.5\n8.5,1.5\n8.5,7.5\n1.5,7.5\n1.5,1.5\n", "loop.csv"), {}, "loop.csv");
  EXPECT_TRUE(path.closed);
  EXPECT_NO_THROW(CheckPathInsideArea(path, HallArea(), "loop.csv"));
  DriveOptions drive;
  drive.speed = 1.0;
  drive.fps = 5.0;
  const size_t lap = DriveAlongPath(path, drive).size();
  EXPECT_NEAR(lap * 0.2, path.Length(), 0.2);
  drive.frames = static_cast<int>(2 * lap);  // a second lap comes back to the start
  const std::vector<SequenceFrame> two = DriveAlongPath(path, drive);
  EXPECT_LT(std::hypot(two[lap].base.x - two[0].base.x, two[lap].base.y - two[0].base.y), 0.25);
  // Through pillar 1 (4.75-5.25, 4.25-4.75): refused, naming the file.
  const SampledPath through =
      PathThroughWaypoints(ParseWaypoints("1,4.5\n8,4.5\n", "pillar.csv"), {}, "pillar.csv");
  try {
    CheckPathInsideArea(through, HallArea(), "pillar.csv");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pillar.csv: the path leaves"), std::string::npos);
  }
  EXPECT_THROW(PathThroughWaypoints(ParseWaypoints("0,0\n4,0\n0,0.001\n", "u.csv"), {}, "u.csv"),
               InputError);  // turns back on itself
}

TEST(HeadPan, ConstantRateBetweenTheAmplitudes) {
  DriveOptions options;
  options.pan_amplitude = DegToRad(35.0);
  options.pan_rate = DegToRad(30.0);
  const double period = 4.0 * 35.0 / 30.0;
  EXPECT_NEAR(HeadPanAt(options, 0.0), 0.0, kTol);
  EXPECT_NEAR(RadToDeg(HeadPanAt(options, 0.5)), 15.0, 1e-9);
  EXPECT_NEAR(RadToDeg(HeadPanAt(options, period / 4)), 35.0, 1e-9);
  EXPECT_NEAR(RadToDeg(HeadPanAt(options, period / 2 + 0.5)), -15.0, 1e-9);
  EXPECT_NEAR(RadToDeg(HeadPanAt(options, 3 * period / 4)), -35.0, 1e-9);
  EXPECT_NEAR(RadToDeg(HeadPanAt(options, period + 0.2)), 6.0, 1e-9);
  for (double t = 0.0; t < 3 * period; t += 0.01) {
    const double rate = RadToDeg(HeadPanAt(options, t + 0.001) - HeadPanAt(options, t)) / 0.001;
    EXPECT_LE(std::abs(rate), 30.0 + 1e-6);
    EXPECT_LE(std::abs(RadToDeg(HeadPanAt(options, t))), 35.0 + 1e-9);
  }
  options.pan_rate = 0.0;  // the sinusoid
  EXPECT_NEAR(HeadPanAt(options, 2.0), options.pan_amplitude, kTol);
}

// 60 m around the hall with the drives' 2.5 % odometry: the relative error over 10 m windows
// stays about the stated share (at most 1.2x: the heading's drift and noise add to the scale
// error), and is not far below it (the drift is there; on a curved path the chord is shorter
// than the distance travelled, so the scale error shows as less than 0.9x).
TEST(Odometry, DriftsByTheStatedShare) {
  DriveOptions drive;
  drive.frames = 1200;
  drive.pan_amplitude = DegToRad(35.0);
  drive.pan_rate = DegToRad(30.0);
  const std::vector<SequenceFrame> frames = DriveAlongLoop(LoopInsideArea(HallArea()), drive);
  constexpr double kDrift = 0.025;
  for (const uint64_t seed : {1u, 2u, 3u, 4u}) {
    const OdometryDrift d = MeasureOdometryDrift(
        frames, SimulateOdometryPriors(frames, OdometryForDrift(kDrift, seed)), 10.0);
    EXPECT_GT(d.windows, 500);
    EXPECT_LE(d.max_share, kMaxDriftRatio * kDrift) << seed;
    EXPECT_GE(d.mean_share, kMinDriftRatio * kDrift) << seed;
  }
  OdometryOptions exact;
  exact.distance_noise = exact.heading_noise = exact.heading_walk = 0.0;
  exact.scale_bias = exact.heading_bias = 0.0;
  EXPECT_LT(MeasureOdometryDrift(frames, SimulateOdometryPriors(frames, exact), 10.0).max_share,
            1e-9);
}

}  // namespace
}  // namespace linetrack
