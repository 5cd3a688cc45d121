// The view-invariant regions against brute-force 3D ray casting on the bundled hall: no edge that
// ray casting finds visible from a pose inside a query may be missing from the query's answer.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <sstream>

#include <Eigen/Geometry>

#include "models/camera.h"
#include "models/cao_reader.h"
#include "models/geometry.h"
#include "models/navigable_area.h"
#include "models/occlusion.h"
#include "models/robot_pose.h"
#include "models/view_invariant_regions.h"
#include "models/wireframe.h"

namespace linetrack {
namespace {

const std::string kHall = std::string(LINETRACK_SOURCE_DIR) + "/models/hall.cao";

constexpr int kPosesPerCamera = 2500;  // per camera and hall: 10,000 poses in all
constexpr double kTiltMaxDeg = 20.0;
constexpr double kTurnDeg = 31.7;
// Mean query size / edge count, measured 0.247 for the paper's QI2 prior (0.5 m, 15 deg) with the
// 640x480 f = 1000 px camera (see docs/models.md), plus a little room.
constexpr double kSelectivityBound = 0.27;

CameraIntrinsics MakeCamera(double focal) {
  CameraIntrinsics camera;
  camera.width = 640;
  camera.height = 480;
  camera.px = camera.py = focal;
  camera.u0 = 320.0;
  camera.v0 = 240.0;
  return camera;
}

// The hall turned by `turn_deg` about the vertical through (2, -3): walls in general directions.
WireframeModel TurnedHall(double turn_deg) {
  CaoModel cao = ReadCao(kHall);
  const Eigen::Rotation2Dd turn(DegToRad(turn_deg));
  for (Eigen::Vector3d& p : cao.points) {
    p.head<2>() = Eigen::Vector2d(2.0, -3.0) + turn * p.head<2>();
  }
  return WireframeModel::FromCao(cao);
}

struct Hall {
  explicit Hall(double turn_deg) : model(TurnedHall(turn_deg)) {}
  WireframeModel model;
  NavigableArea area = NavigableArea::FromModel(model);
  ViewInvariantRegions regions = ViewInvariantRegions::Build(model, area);
  OcclusionTester occlusion{model};
};

const Hall& TheHall(double turn_deg = 0.0) {
  static const Hall straight(0.0), turned(kTurnDeg);
  return turn_deg == 0.0 ? straight : turned;
}

Eigen::Vector2d RandomNavigablePoint(const NavigableArea& area, std::mt19937* rng) {
  std::uniform_real_distribution<double> ux(area.BoundsMin().x(), area.BoundsMax().x());
  std::uniform_real_distribution<double> uy(area.BoundsMin().y(), area.BoundsMax().y());
  for (;;) {
    const Eigen::Vector2d p(ux(*rng), uy(*rng));
    if (area.Contains(p)) return p;
  }
}

// (focal length in pixels, turn of the hall in degrees)
class VirRayCasting : public ::testing::TestWithParam<std::tuple<double, double>> {};

TEST_P(VirRayCasting, NoVisibleEdgeIsMissing) {
  const auto [focal, turn_deg] = GetParam();
  const Hall& hall = TheHall(turn_deg);
  const CameraIntrinsics camera = MakeCamera(focal);
  const double half_width = BearingHalfWidth(camera, 0.0, DegToRad(kTiltMaxDeg));
  std::mt19937 rng(20240611u + static_cast<unsigned>(focal + turn_deg));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int misses = 0, visible_total = 0;
  std::ostringstream first_misses;
  for (int i = 0; i < kPosesPerCamera; ++i) {
    const Eigen::Vector2d p = RandomNavigablePoint(hall.area, &rng);
    RobotPose pose;
    pose.x = p.x();
    pose.y = p.y();
    pose.heading = kPi * (2.0 * unit(rng) - 1.0);
    pose.height = 0.5 + 1.5 * unit(rng);
    pose.tilt = DegToRad(kTiltMaxDeg) * unit(rng);
    // A query whose disk and heading interval contain the true pose anywhere; every other pose
    // sits on the query's boundary (disk rim, end of the heading interval), the hardest case.
    VisibilityQuery query;
    query.radius = 0.2 + 1.8 * unit(rng);
    query.heading_margin = DegToRad(5.0 + 40.0 * unit(rng));
    const bool on_boundary = i % 2 == 1;
    const double r = query.radius * (on_boundary ? 1.0 : std::sqrt(unit(rng)));
    const double a = 2.0 * kPi * unit(rng);
    const double offset = on_boundary ? (unit(rng) < 0.5 ? -1.0 : 1.0) : 2.0 * unit(rng) - 1.0;
    query.centre = p + r * Eigen::Vector2d(std::cos(a), std::sin(a));
    query.heading = WrapAngle(pose.heading + query.heading_margin * offset);
    query.bearing_half_width = half_width;
    query.camera_z = pose.height;  // the storey's walls also hide edges from the disk itself
    const std::vector<int> ids = hall.regions.Query(query);
    ASSERT_TRUE(std::is_sorted(ids.begin(), ids.end()));
    ASSERT_TRUE(std::adjacent_find(ids.begin(), ids.end()) == ids.end());
    for (const ProjectedEdge& piece :
         ProjectVisibleEdges(hall.model, hall.occlusion, CamFromWorld(pose), camera)) {
      ++visible_total;
      if (std::binary_search(ids.begin(), ids.end(), piece.edge_id)) continue;
      if (++misses <= 5) {
        first_misses << "edge " << piece.edge_id << " from (" << pose.x << ", " << pose.y
                     << ") heading " << RadToDeg(pose.heading) << " deg height " << pose.height
                     << " tilt " << RadToDeg(pose.tilt) << "; ";
      }
    }
  }
  EXPECT_GT(visible_total, kPosesPerCamera);  // the scene shows edges, the test can fail
  EXPECT_EQ(misses, 0) << first_misses.str();
}

INSTANTIATE_TEST_SUITE_P(NarrowAndWideCameras, VirRayCasting,
                         ::testing::Combine(::testing::Values(1000.0, 300.0),
                                            ::testing::Values(0.0, kTurnDeg)));

TEST(VirSelectivity, QueryKeepsAFractionOfTheEdges) {
  const Hall& hall = TheHall();
  const double half_width = BearingHalfWidth(MakeCamera(1000.0), 0.0, DegToRad(kTiltMaxDeg));
  std::mt19937 rng(7u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  constexpr int kQueries = 2000;
  double kept = 0.0;
  for (int i = 0; i < kQueries; ++i) {
    VisibilityQuery query;
    query.centre = RandomNavigablePoint(hall.area, &rng);
    query.radius = 0.5;
    query.heading = kPi * (2.0 * unit(rng) - 1.0);
    query.heading_margin = DegToRad(15.0);
    query.bearing_half_width = half_width;
    kept += static_cast<double>(hall.regions.Query(query).size());
  }
  const double selectivity = kept / kQueries / static_cast<double>(hall.model.edges().size());
  RecordProperty("selectivity", std::to_string(selectivity));
  EXPECT_GT(selectivity, 0.05);  // edges are found at all
  EXPECT_LT(selectivity, kSelectivityBound);
}

}  // namespace
}  // namespace linetrack
