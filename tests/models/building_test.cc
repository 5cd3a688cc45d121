// The generated building: its size, its faces facing the free space as written (and coming back so
// from reversed), two storeys, a navigable area per storey joining rooms and corridor through the
// doors, regions that keep each storey to its own edges, and no finding of the model checks.
#include "models/synth/synthetic_building.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "models/model_checks.h"
#include "models/navigable_area.h"
#include "models/occlusion.h"
#include "models/robot_pose.h"
#include "models/synth/synthetic_scenes.h"
#include "models/view_invariant_regions.h"
#include "models/wireframe.h"

namespace linetrack {
namespace {

constexpr double kAreaTolM2 = 1e-6;
constexpr double kHeightTolM = 1e-9;
constexpr double kSlabTolM = 0.05;
// Footprint of a radiator (models/synth/synthetic_building.cc): 1.2 m long, 0.12 m deep (m^2).
constexpr double kRadiatorArea = 1.2 * 0.12;

class Building : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    building_ = new SyntheticBuilding(GenerateBuilding(BuildingSpec()));
    model_ = new WireframeModel(WireframeModel::FromCao(building_->cao));
    area_ = new NavigableArea(NavigableArea::FromModel(*model_));
  }
  static void TearDownTestSuite() {
    delete area_;
    delete model_;
    delete building_;
  }
  static SyntheticBuilding* building_;
  static WireframeModel* model_;
  static NavigableArea* area_;
};

SyntheticBuilding* Building::building_ = nullptr;
WireframeModel* Building::model_ = nullptr;
NavigableArea* Building::area_ = nullptr;

TEST_F(Building, HasTheSizeOfTheScaleTargets) {
  int rooms = 0;
  for (const BuildingSpace& space : building_->spaces)
    rooms += space.corridor ? 0 : 1;
  EXPECT_EQ(rooms, 36);
  EXPECT_GE(model_->edges().size(), 2000u);
  ASSERT_EQ(model_->storeys().size(), 2u);
  const BuildingSpec spec;
  EXPECT_NEAR(model_->storeys()[0].floor_z, 0.0, kHeightTolM);
  EXPECT_NEAR(model_->storeys()[0].top_z, spec.storey_height, kHeightTolM);
  EXPECT_NEAR(model_->storeys()[1].floor_z, spec.storey_height + spec.slab, kHeightTolM);
}

TEST_F(Building, IsWrittenFacingTheFreeSpace) {
  EXPECT_TRUE(model_->oriented());
  EXPECT_TRUE(model_->orientation_summary().empty()) << model_->orientation_summary().front();
}

TEST_F(Building, ReversedFacesComeBackAsWritten) {
  std::mt19937 rng(7u);
  std::bernoulli_distribution pick(0.5);
  CaoModel reversed = building_->cao;
  for (std::vector<int>& face : reversed.faces) {
    if (pick(rng)) std::reverse(face.begin(), face.end());
  }
  const WireframeModel turned = WireframeModel::FromCao(reversed);
  ASSERT_EQ(turned.faces().size(), model_->faces().size());
  for (size_t f = 0; f < turned.faces().size(); ++f)
    EXPECT_EQ(turned.faces()[f].vertices, model_->faces()[f].vertices) << "face " << f;
  ASSERT_EQ(turned.edges().size(), model_->edges().size());
  for (size_t e = 0; e < turned.edges().size(); ++e) {
    EXPECT_EQ(turned.edges()[e].v0, model_->edges()[e].v0) << "edge " << e;
    EXPECT_EQ(turned.edges()[e].v1, model_->edges()[e].v1) << "edge " << e;
  }
}

TEST_F(Building, EachStoreyIsOneAreaJoinedThroughTheDoors) {
  ASSERT_EQ(area_->parts().size(), 2u);
  const BuildingSpec spec;
  for (int s = 0; s < 2; ++s) {
    // Rooms, corridor and door thresholds, minus the footprints of the pillars, low boxes,
    // cabinets and radiators (1.2 m x 0.12 m under each room's window: rooms >= 3 m wide).
    double expected = 0.0;
    int rooms = 0;
    for (size_t k = 0; k < building_->spaces.size(); ++k) {
      const BuildingSpace& space = building_->spaces[k];
      if (space.storey != s) continue;
      expected += (space.hi - space.lo).prod();
      if (space.corridor) continue;
      const int kind = (s * 2 * spec.rooms_per_side + rooms) % 3;
      expected += spec.door_width * spec.wall - (kind == 0 ? 0.16 : kind == 1 ? 0.6 : 0.6);
      ASSERT_GE(space.hi.x() - space.lo.x(), 3.0) << space.name;
      expected -= kRadiatorArea;
      ++rooms;
    }
    EXPECT_NEAR(area_->Area(s), expected, kAreaTolM2) << "storey " << s;
    for (const BuildingSpace& space : building_->spaces) {
      if (space.storey != s) continue;
      // A point 0.5 m from the space's west wall, half way across (clear of the furniture).
      const Eigen::Vector2d p(space.lo.x() + 0.5, 0.5 * (space.lo.y() + space.hi.y()));
      EXPECT_TRUE(area_->Contains(p, s)) << space.name;
    }
  }
}

TEST_F(Building, RegionsKeepEachStoreyToItsOwnEdges) {
  const ViewInvariantRegions regions = ViewInvariantRegions::Build(*model_, *area_);
  const BuildingSpec spec;
  for (int s = 0; s < 2; ++s) {
    const BuildingSpace& corridor = building_->spaces[building_->spaces.size() - 2 + s];
    VisibilityQuery query;
    query.centre = 0.5 * (corridor.lo + corridor.hi);
    query.radius = 0.5;
    query.heading_margin = kPi;
    query.camera_z = corridor.floor_z + 1.3;
    const std::vector<int> ids = regions.Query(query);
    ASSERT_FALSE(ids.empty());
    // The slab hides the other storey: storey 0 lists nothing above its ceiling, storey 1
    // nothing below its floor.
    for (int id : ids) {
      const ModelEdge& edge = model_->edges()[id];
      if (s == 0) {
        EXPECT_LE(std::min(edge.segment.a.z(), edge.segment.b.z()), spec.storey_height + kSlabTolM)
            << "edge " << id;
      } else {
        EXPECT_GE(std::max(edge.segment.a.z(), edge.segment.b.z()),
                  spec.storey_height + spec.slab - kSlabTolM)
            << "edge " << id;
      }
    }
  }
}

// From a room's corner by its neighbour's wall, looking past its door: the query keeps few edges
// of other spaces that ray casting never sees from the disk (behind the room's corners, which
// neither wall hides alone), and misses none it sees.
TEST_F(Building, QueryPastARoomsCornerKeepsLittleItCannotSee) {
  const ViewInvariantRegions regions = ViewInvariantRegions::Build(*model_, *area_);
  const OcclusionTester occlusion(*model_);
  const CameraIntrinsics camera = PaperSyntheticCamera();
  const BuildingSpace& room = building_->spaces[1];  // s0-south-1: x 4.4-8, y 0.2-4.2, door north
  ASSERT_EQ(room.name, "s0-south-1");
  constexpr double kTilt = 0.05, kHeight = 1.35;  // radians, metres
  VisibilityQuery query;
  query.centre = {4.59, 3.50};
  query.radius = 0.3;
  query.heading = DegToRad(13.2);
  query.heading_margin = DegToRad(10.0);
  query.bearing_half_width = BearingHalfWidth(camera, kTilt, kTilt);
  query.camera_z = kHeight;
  const std::vector<int> ids = regions.Query(query);
  constexpr double kOwn = 0.35;  // a room's own edges reach this far past its free rectangle
  const auto own = [&](const Eigen::Vector3d& p) {
    return p.x() >= room.lo.x() - kOwn && p.x() <= room.hi.x() + kOwn &&
           p.y() >= room.lo.y() - kOwn && p.y() <= room.hi.y() + kOwn;
  };
  std::mt19937 rng(3u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<char> seen(model_->edges().size(), 0);
  int misses = 0;
  for (int i = 0; i < 600; ++i) {
    const double r = query.radius * (i % 3 == 0 ? 1.0 : std::sqrt(unit(rng)));
    const double a = 2.0 * kPi * unit(rng);
    const Eigen::Vector2d p = query.centre + r * Eigen::Vector2d(std::cos(a), std::sin(a));
    if (!area_->Contains(p, 0)) continue;
    const RobotPose pose{p.x(), p.y(),
                         query.heading + query.heading_margin * (2.0 * unit(rng) - 1.0), kHeight,
                         kTilt};
    for (const ProjectedEdge& piece :
         ProjectVisibleEdges(*model_, occlusion, CamFromWorld(pose), camera)) {
      seen[piece.edge_id] = 1;
      misses += std::binary_search(ids.begin(), ids.end(), piece.edge_id) ? 0 : 1;
    }
  }
  int other = 0, other_seen = 0;
  for (int id : ids) {
    const Segment3& s = model_->edges()[id].segment;
    if (own(s.a) || own(s.b)) continue;
    ++other;
    other_seen += seen[id];
  }
  EXPECT_EQ(misses, 0);
  EXPECT_GT(other_seen, 5);  // the corridor and the room across, through the door
  // 81 edges of other spaces before corners were tested (10 seen); 27 with them.
  EXPECT_LE(other - other_seen, 20);
}

TEST_F(Building, PassesTheModelChecks) {
  const std::vector<ModelFinding> findings = CheckModel(*model_);
  EXPECT_TRUE(findings.empty()) << findings.front().message;
}

// On a small building (2 storeys of 2 rooms a side), the regions' lists equal, bit for bit,
// those of testing every edge of the storey directly (ViewInvariantRegionsOptions::direct_lists).
TEST(SmallBuilding, RegionListsEqualTheDirectTest) {
  BuildingSpec spec;
  spec.rooms_per_side = 2;
  const WireframeModel model = WireframeModel::FromCao(GenerateBuilding(spec).cao);
  const NavigableArea area = NavigableArea::FromModel(model);
  ViewInvariantRegionsOptions direct;
  direct.direct_lists = true;
  const ViewInvariantRegions a = ViewInvariantRegions::Build(model, area);
  const ViewInvariantRegions b = ViewInvariantRegions::Build(model, area, direct);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 100);
  size_t entries = 0;
  for (int r = 0; r < a.size(); ++r) {
    const ViewRegion &x = a.regions()[r], &y = b.regions()[r];
    ASSERT_EQ(x.polygon.vertices, y.polygon.vertices) << r;
    ASSERT_EQ(x.visible.size(), y.visible.size()) << r;
    for (size_t k = 0; k < x.visible.size(); ++k) {
      const RegionEdge &e = x.visible[k], &f = y.visible[k];
      EXPECT_TRUE(e.edge_id == f.edge_id && e.diamond_min == f.diamond_min &&
                  e.diamond_max == f.diamond_max && e.all_bearings == f.all_bearings)
          << "region " << r << " entry " << k;
    }
    entries += x.visible.size();
  }
  EXPECT_GT(entries, 0u);
}

// In rooms joined by doors to a corridor, where the query's walls hide edges from the disk
// itself: no edge that ray casting finds visible from a pose inside a query is missing.
TEST(SmallBuilding, QueriesMissNoEdgeThatRayCastingSees) {
  BuildingSpec spec;
  spec.rooms_per_side = 2;
  const WireframeModel model = WireframeModel::FromCao(GenerateBuilding(spec).cao);
  const NavigableArea area = NavigableArea::FromModel(model);
  const ViewInvariantRegions vir = ViewInvariantRegions::Build(model, area);
  const OcclusionTester occlusion(model);
  const CameraIntrinsics camera = PaperSyntheticCamera();
  constexpr double kTiltMax = 0.2;  // radians
  const double half_width = BearingHalfWidth(camera, 0.0, kTiltMax);
  std::mt19937 rng(41u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector2d lo = area.BoundsMin(), hi = area.BoundsMax();
  int misses = 0, visible = 0;
  for (int i = 0; i < 600; ++i) {
    const int storey = i % 2;
    Eigen::Vector2d p;
    do {
      p = lo + Eigen::Vector2d(unit(rng), unit(rng)).cwiseProduct(hi - lo);
    } while (!area.Contains(p, storey));
    RobotPose pose;
    pose.x = p.x();
    pose.y = p.y();
    pose.heading = kPi * (2.0 * unit(rng) - 1.0);
    pose.height = area.storeys()[storey].floor_z + 0.5 + 1.5 * unit(rng);
    pose.tilt = kTiltMax * unit(rng);
    // The pose on the rim of the query's disk and at an end of its headings, the hardest case.
    VisibilityQuery query;
    query.radius = 0.2 + 0.8 * unit(rng);
    query.heading_margin = DegToRad(5.0 + 20.0 * unit(rng));
    const double a = 2.0 * kPi * unit(rng);
    query.centre = p + query.radius * Eigen::Vector2d(std::cos(a), std::sin(a));
    query.heading = pose.heading + (unit(rng) < 0.5 ? -1.0 : 1.0) * query.heading_margin;
    query.bearing_half_width = half_width;
    query.camera_z = pose.height;
    const std::vector<int> ids = vir.Query(query);
    for (const ProjectedEdge& piece :
         ProjectVisibleEdges(model, occlusion, CamFromWorld(pose), camera)) {
      ++visible;
      if (!std::binary_search(ids.begin(), ids.end(), piece.edge_id)) {
        ++misses;
        ADD_FAILURE() << "edge " << piece.edge_id << " missing, pose " << i;
      }
    }
  }
  EXPECT_GT(visible, 600);  // the poses see edges: the test can fail
  EXPECT_EQ(misses, 0);
}

TEST(BuildingAlone, EveryRoomAloneEnclosesItsSpace) {
  const BuildingSpec spec;
  const SyntheticBuilding building = GenerateBuilding(spec);
  for (size_t k = 0; k < building.spaces.size(); ++k) {
    const WireframeModel alone = WireframeModel::FromCao(SpaceAlone(spec, static_cast<int>(k)));
    EXPECT_TRUE(alone.oriented()) << building.spaces[k].name;
    EXPECT_TRUE(alone.orientation_summary().empty())
        << building.spaces[k].name << ": " << alone.orientation_summary().front();
    const NavigableArea area = NavigableArea::FromModel(alone);
    EXPECT_EQ(area.parts().size(), 1u) << building.spaces[k].name;
  }
}

}  // namespace
}  // namespace linetrack
