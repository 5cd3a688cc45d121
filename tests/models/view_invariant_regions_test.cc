// The view-invariant regions: the bearing half-width against brute force, regions that
// partition the navigable area, occlusion by a wall between two rooms and behind a pillar, and
// the query's contract.
#include "models/view_invariant_regions.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "models/cao_reader.h"
#include "models/convex_polygon.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/occlusion.h"
#include "models/robot_pose.h"

namespace linetrack {
namespace {

const std::string kModels = std::string(LINETRACK_SOURCE_DIR) + "/models";
constexpr double kAngleTolRad = 1e-12;
constexpr double kAreaTolM2 = 1e-6;

CameraIntrinsics MakeCamera(double focal, double u0 = 320.0, double v0 = 240.0) {
  CameraIntrinsics camera;
  camera.width = 640;
  camera.height = 480;
  camera.px = camera.py = focal;
  camera.u0 = u0;
  camera.v0 = v0;
  return camera;
}

// Largest |atan2(mL_x, mL_z)| over the image border (every pixel) of a camera rolled by `roll`
// and tilts every 0.1 degree; pi when a ray has mL_z <= 0.
double BruteForceHalfWidth(const CameraIntrinsics& camera, double tilt_min, double tilt_max,
                           double roll = 0.0) {
  std::vector<Eigen::Vector2d> border;
  for (int u = 0; u < camera.width; ++u)
    border.push_back({u, 0.0}), border.push_back({u, camera.height - 1.0});
  for (int v = 0; v < camera.height; ++v)
    border.push_back({0.0, v}), border.push_back({camera.width - 1.0, v});
  const int steps = std::max(1, static_cast<int>(RadToDeg(tilt_max - tilt_min) / 0.1));
  double widest = 0.0;
  for (int k = 0; k <= steps; ++k) {
    const Eigen::Matrix3d level = LevelFromCam(tilt_min + (tilt_max - tilt_min) * k / steps);
    for (const Eigen::Vector2d& uv : border) {
      const Eigen::Vector2d rolled = camera.Ray(camera.Undistort(uv)).head<2>();
      const Eigen::Vector3d m = level * UnrollImagePoint(rolled, roll).homogeneous();
      if (m.z() <= 0.0) return kPi;
      widest = std::max(widest, std::abs(std::atan2(m.x(), m.z())));
    }
  }
  return widest;
}

TEST(BearingHalfWidth, MatchesBruteForceOverTheImageBorder) {
  CameraIntrinsics distorted = MakeCamera(400.0);
  distorted.has_distortion = true;
  distorted.kud = -0.25;
  distorted.kdu = 0.3;
  const struct {
    CameraIntrinsics camera;
    double tilt_min_deg, tilt_max_deg, tolerance;
  } cases[] = {
      {MakeCamera(1000.0), 0.0, 20.0, kAngleTolRad},
      {MakeCamera(300.0), 0.0, 20.0, kAngleTolRad},
      {MakeCamera(300.0), -35.0, 10.0, kAngleTolRad},
      {MakeCamera(500.0, 60.0, 450.0), 5.0, 40.0, kAngleTolRad},  // principal point off-centre
      {distorted, 0.0, 30.0, 2e-3},  // the box of the undistorted border: a bound, not exact
  };
  for (const auto& c : cases) {
    const double computed =
        BearingHalfWidth(c.camera, DegToRad(c.tilt_min_deg), DegToRad(c.tilt_max_deg));
    const double brute =
        BruteForceHalfWidth(c.camera, DegToRad(c.tilt_min_deg), DegToRad(c.tilt_max_deg));
    EXPECT_GE(computed, brute - kAngleTolRad) << "f " << c.camera.px << " tilt " << c.tilt_max_deg;
    EXPECT_LE(computed, brute + c.tolerance) << "f " << c.camera.px << " tilt " << c.tilt_max_deg;
  }
  // The paper's camera, level: the left column u = 0 is 320 px from the centre.
  EXPECT_NEAR(BearingHalfWidth(MakeCamera(1000.0), 0.0, 0.0), std::atan(0.32), kAngleTolRad);
}

TEST(BearingHalfWidth, BoundsARolledCameraOverTheImageBorder) {
  const struct {
    CameraIntrinsics camera;
    double tilt_deg, roll_deg, tolerance;
  } cases[] = {
      {MakeCamera(1000.0), 0.0, 5.0, 0.01},    // the box of the turned border: a bound
      {MakeCamera(1000.0), 20.0, -5.0, 0.01},  //
      {MakeCamera(300.0), 10.0, 1.5, 0.01},    //
      {MakeCamera(500.0, 60.0, 450.0), 15.0, 180.0, kAngleTolRad},  // upside down: exact
  };
  for (const auto& c : cases) {
    const double tilt = DegToRad(c.tilt_deg), roll = DegToRad(c.roll_deg);
    const double computed = BearingHalfWidth(c.camera, tilt, tilt, roll);
    const double brute = BruteForceHalfWidth(c.camera, tilt, tilt, roll);
    EXPECT_GE(computed, brute - kAngleTolRad) << "roll " << c.roll_deg;
    EXPECT_LE(computed, brute + c.tolerance) << "roll " << c.roll_deg;
  }
  EXPECT_THROW(BearingHalfWidth(MakeCamera(500.0), 0.0, 0.1, std::nan("")), InputError);
}

TEST(BearingHalfWidth, IsPiWhenTheNadirCanBeInTheImage) {
  // Wide camera: the bottom row (m_y = 239 / 300) looks past the nadir once
  // tan(tilt) >= 300 / 239, i.e. tilt >= 51.5 degrees.
  const CameraIntrinsics wide = MakeCamera(300.0);
  EXPECT_EQ(BruteForceHalfWidth(wide, 0.0, DegToRad(60.0)), kPi);
  EXPECT_EQ(BearingHalfWidth(wide, 0.0, DegToRad(60.0)), kPi);
  EXPECT_LT(BearingHalfWidth(wide, 0.0, DegToRad(45.0)), 0.5 * kPi);
}

TEST(BearingHalfWidth, RejectsBadInput) {
  CameraIntrinsics no_size = MakeCamera(500.0);
  no_size.width = 0;
  EXPECT_THROW(BearingHalfWidth(no_size, 0.0, 0.1), InputError);
  EXPECT_THROW(BearingHalfWidth(MakeCamera(500.0), 0.2, 0.1), InputError);
  EXPECT_THROW(BearingHalfWidth(MakeCamera(500.0), 0.0, 2.0), InputError);
}

struct Built {
  WireframeModel model;
  NavigableArea area;
  ViewInvariantRegions vir;
};

Built BuildFor(const WireframeModel& model, const ViewInvariantRegionsOptions& options = {}) {
  NavigableArea area = NavigableArea::FromModel(model);
  ViewInvariantRegions vir = ViewInvariantRegions::Build(model, area, options);
  return {model, std::move(area), std::move(vir)};
}

std::vector<int> RegionsContaining(const ViewInvariantRegions& vir, const Eigen::Vector2d& p) {
  std::vector<int> ids;
  for (int r = 0; r < vir.size(); ++r) {
    if (ConvexContains(vir.regions()[r].polygon.vertices, p)) ids.push_back(r);
  }
  return ids;
}

bool Lists(const ViewRegion& region, int edge_id) {
  return std::any_of(region.visible.begin(), region.visible.end(),
                     [&](const RegionEdge& e) { return e.edge_id == edge_id; });
}

class RegionsPartition : public ::testing::TestWithParam<std::tuple<const char*, double>> {};

TEST_P(RegionsPartition, TheNavigableArea) {
  const auto [name, grid_pitch] = GetParam();
  ViewInvariantRegionsOptions options;
  options.grid_pitch = grid_pitch;
  const Built b = BuildFor(WireframeModel::Load(kModels + "/" + name), options);
  ASSERT_GT(b.vir.size(), 0);
  double total = 0.0;
  for (const ViewRegion& region : b.vir.regions()) {
    EXPECT_TRUE(IsConvexRing(region.polygon.vertices, 1e-9));
    total += region.polygon.SignedArea();
    for (size_t k = 1; k < region.visible.size(); ++k) {
      EXPECT_LT(region.visible[k - 1].edge_id, region.visible[k].edge_id);
    }
    for (const RegionEdge& e : region.visible) {
      if (e.all_bearings) continue;
      EXPECT_GE(e.diamond_min, 0.0);
      EXPECT_LT(e.diamond_min, 4.0);
      EXPECT_GE(e.diamond_max, e.diamond_min);
      EXPECT_LT(e.diamond_max - e.diamond_min, 2.0);
    }
  }
  EXPECT_NEAR(total, b.area.Area(), kAreaTolM2);
  std::mt19937 rng(11u);
  std::uniform_real_distribution<double> ux(b.area.BoundsMin().x(), b.area.BoundsMax().x());
  std::uniform_real_distribution<double> uy(b.area.BoundsMin().y(), b.area.BoundsMax().y());
  int tested = 0;
  while (tested < 10000) {
    const Eigen::Vector2d p(ux(rng), uy(rng));
    const bool in_area = b.area.InsideBoundary(p);
    if (!in_area) {
      EXPECT_TRUE(RegionsContaining(b.vir, p).empty());
      continue;
    }
    ++tested;
    EXPECT_EQ(RegionsContaining(b.vir, p).size(), 1u) << p.transpose();
  }
}

INSTANTIATE_TEST_SUITE_P(BundledModels, RegionsPartition,
                         ::testing::Combine(::testing::Values("hall.cao", "room.cao"),
                                            ::testing::Values(0.0, 1.0)));

// The same polygons and lists, bit for bit.
void ExpectSameRegions(const ViewInvariantRegions& a, const ViewInvariantRegions& b) {
  ASSERT_EQ(a.size(), b.size());
  for (int r = 0; r < a.size(); ++r) {
    const ViewRegion &x = a.regions()[r], &y = b.regions()[r];
    EXPECT_EQ(x.polygon.vertices, y.polygon.vertices) << r;
    ASSERT_EQ(x.visible.size(), y.visible.size()) << r;
    for (size_t k = 0; k < x.visible.size(); ++k) {
      EXPECT_EQ(x.visible[k].edge_id, y.visible[k].edge_id);
      EXPECT_EQ(x.visible[k].diamond_min, y.visible[k].diamond_min);
      EXPECT_EQ(x.visible[k].diamond_max, y.visible[k].diamond_max);
      EXPECT_EQ(x.visible[k].all_bearings, y.visible[k].all_bearings);
    }
  }
}

// The lists are computed on several threads: any number gives the same regions, bit for bit.
TEST(ViewInvariantRegions, ThreadsDoNotChangeTheRegions) {
  const WireframeModel model = WireframeModel::Load(kModels + "/office.cao");
  ViewInvariantRegionsOptions one, three;
  one.threads = 1;
  three.threads = 3;
  const Built a = BuildFor(model, one), b = BuildFor(model, three);
  ASSERT_GT(a.vir.size(), 3 * 64);  // enough regions for three threads
  ExpectSameRegions(a.vir, b.vir);
}

// A region tests only its cell's edges against the occluders that can hide each from a part of
// the cell: the same lists, bit for bit, as testing every edge of the storey directly.
TEST(ViewInvariantRegions, ListsEqualTheDirectTest) {
  for (const char* name : {"hall.cao", "office.cao"}) {
    SCOPED_TRACE(name);
    const WireframeModel model = WireframeModel::Load(kModels + "/" + name);
    ViewInvariantRegionsOptions direct;
    direct.direct_lists = true;
    const Built a = BuildFor(model), b = BuildFor(model, direct);
    ASSERT_GT(a.vir.size(), 100);
    ExpectSameRegions(a.vir, b.vir);
  }
}

TEST(ViewInvariantRegions, HallOccludersAndSolids) {
  const Built b = BuildFor(WireframeModel::Load(kModels + "/hall.cao"));
  EXPECT_EQ(b.vir.occluders().size(), 15u);  // 4 walls, 3 partition faces, 2 x 4 pillar faces
  EXPECT_EQ(b.vir.solids().size(), 3u);      // the two pillars and the partition
  ViewInvariantRegionsOptions taller;
  taller.camera_top = 3.5;  // a camera above the walls sees over them
  EXPECT_TRUE(BuildFor(b.model, taller).vir.occluders().empty());
  ViewInvariantRegionsOptions bad;
  bad.grid_pitch = -1.0;
  EXPECT_THROW(ViewInvariantRegions::Build(b.model, b.area, bad), InputError);
}

int EdgeBetween(const WireframeModel& model, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  for (const ModelEdge& e : model.edges()) {
    if (((e.segment.a - a).norm() < 1e-9 && (e.segment.b - b).norm() < 1e-9) ||
        ((e.segment.a - b).norm() < 1e-9 && (e.segment.b - a).norm() < 1e-9)) {
      return e.id;
    }
  }
  return -1;
}

TEST(ViewInvariantRegions, PillarHidesItsFarFaceFromTheRegionBehindIt) {
  const Built b = BuildFor(WireframeModel::Load(kModels + "/hall.cao"));
  // pillar1 spans x 4.75..5.25, y 4.25..4.75; its north face's top edge is seen from the north.
  const int far_edge = EdgeBetween(b.model, {5.25, 4.75, 3.0}, {4.75, 4.75, 3.0});
  ASSERT_GE(far_edge, 0);
  for (int r : RegionsContaining(b.vir, {5.0, 2.0})) {
    EXPECT_FALSE(Lists(b.vir.regions()[r], far_edge));
  }
  const std::vector<int> north = RegionsContaining(b.vir, {5.0, 6.0});
  ASSERT_FALSE(north.empty());
  EXPECT_TRUE(Lists(b.vir.regions()[north.front()], far_edge));
}

// Two 5 x 5 rooms side by side (x 0..10, y 0..5, 2.5 m high) joined by a door: the dividing
// wall x = 5 runs from y = 0 to y = 3, two-sided. A lamp post (vertical 3D line) stands in the
// east room at (8, 1).
WireframeModel TwoRooms() {
  const std::string text =
      "V1\n14\n"
      "0 0 0\n10 0 0\n10 5 0\n0 5 0\n0 0 2.5\n10 0 2.5\n10 5 2.5\n0 5 2.5\n"  // 0-7 the shell
      "5 0 0\n5 3 0\n5 3 2.5\n5 0 2.5\n"                                      // 8-11 the wall
      "8 1 0\n8 1 2.5\n"                                                      // 12-13 the post
      "1\n12 13 name=\"post\"\n0\n6\n"
      "4 0 4 5 1\n4 1 5 6 2\n4 2 6 7 3\n4 3 7 4 0\n"  // the shell's walls, facing in
      "4 8 11 10 9\n4 8 9 10 11\n"                    // the dividing wall, both sides
      "0\n0\n";
  return WireframeModel::FromCao(ParseCao(text, "two_rooms.cao", nullptr));
}

TEST(ViewInvariantRegions, WallHidesTheOtherRoomsPost) {
  const Built b = BuildFor(TwoRooms());
  const int post = 0;  // the one 3D line comes first
  ASSERT_TRUE(b.model.edges()[post].vertical);
  EXPECT_EQ(b.area.source(), "walls (6 faces)");
  // Behind the wall: (2, 1) to (8, 1) crosses x = 5 at y = 1; (1, 4.5) crosses it at y = 2.5.
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(2.0, 1.0), Eigen::Vector2d(1.0, 4.5)}) {
    const std::vector<int> regions = RegionsContaining(b.vir, p);
    ASSERT_FALSE(regions.empty());
    for (int r : regions)
      EXPECT_FALSE(Lists(b.vir.regions()[r], post)) << p.transpose();
  }
  // Through the door: (4, 4.6) to (8, 1) crosses x = 5 at y = 3.7.
  const std::vector<int> door_regions = RegionsContaining(b.vir, {4.0, 4.6});
  ASSERT_FALSE(door_regions.empty());
  EXPECT_TRUE(Lists(b.vir.regions()[door_regions.front()], post));

  // Ray casting agrees, and so does a query around each place, whatever the heading.
  const OcclusionTester occlusion(b.model);
  const CameraIntrinsics camera = MakeCamera(300.0);
  auto sees_post = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2d to_post = Eigen::Vector2d(8.0, 1.0) - p;
    const RobotPose pose{p.x(), p.y(), std::atan2(to_post.y(), to_post.x()), 1.2, 0.0};
    const auto pieces = ProjectVisibleEdges(b.model, occlusion, CamFromWorld(pose), camera);
    return std::any_of(pieces.begin(), pieces.end(),
                       [&](const ProjectedEdge& e) { return e.edge_id == post; });
  };
  auto query_has_post = [&](const Eigen::Vector2d& p) {
    VisibilityQuery query;
    query.centre = p;
    query.radius = 0.1;
    query.heading_margin = kPi;
    const std::vector<int> ids = b.vir.Query(query);
    return std::binary_search(ids.begin(), ids.end(), post);
  };
  EXPECT_FALSE(sees_post({2.0, 1.0}));
  EXPECT_FALSE(query_has_post({2.0, 1.0}));
  EXPECT_TRUE(sees_post({4.0, 4.6}));
  EXPECT_TRUE(query_has_post({4.0, 4.6}));
}

TEST(ViewInvariantRegions, QueryContract) {
  const Built b = BuildFor(WireframeModel::Load(kModels + "/hall.cao"));
  VisibilityQuery query;
  query.centre = {7.0, 2.0};
  query.radius = 0.5;
  query.heading = DegToRad(90.0);
  query.heading_margin = DegToRad(10.0);
  query.bearing_half_width = DegToRad(18.0);
  const std::vector<int> ids = b.vir.Query(query);
  ASSERT_FALSE(ids.empty());
  EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
  EXPECT_TRUE(std::adjacent_find(ids.begin(), ids.end()) == ids.end());
  // Looking north from (7, 2) the south wall's window is behind the camera.
  const int sill = EdgeBetween(b.model, {6.0, 0.0, 1.0}, {8.0, 0.0, 1.0});
  ASSERT_GE(sill, 0);
  EXPECT_FALSE(std::binary_search(ids.begin(), ids.end(), sill));
  query.heading = DegToRad(-90.0);
  const std::vector<int> south = b.vir.Query(query);
  EXPECT_TRUE(std::binary_search(south.begin(), south.end(), sill));
  // A wider heading interval keeps more; every heading keeps the union of the lists.
  query.heading_margin = kPi;
  const std::vector<int> all = b.vir.Query(query);
  EXPECT_TRUE(std::includes(all.begin(), all.end(), ids.begin(), ids.end()));
  EXPECT_TRUE(std::includes(all.begin(), all.end(), south.begin(), south.end()));
  EXPECT_GT(all.size(), std::max(ids.size(), south.size()));
  // Far outside the model nothing is seen; bad fields are rejected.
  query.centre = {100.0, 100.0};
  EXPECT_TRUE(b.vir.Query(query).empty());
  query.radius = std::nan("");
  EXPECT_THROW(b.vir.Query(query), InputError);
}

}  // namespace
}  // namespace linetrack
