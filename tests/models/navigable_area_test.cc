// The navigable area derived from the walls against the hand-written one, on the bundled models,
// a turned hall, ViSP's cube (no enclosing walls) and small hand-made models; bad sidecar files.
#include "models/navigable_area.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <random>

#include "models/cao_reader.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/wireframe.h"

namespace linetrack {
namespace {

const std::string kModels = std::string(LINETRACK_SOURCE_DIR) + "/models";
const std::string kHallSidecar = std::string(LINETRACK_SOURCE_DIR) + "/tests/data/hall.nav.json";
const std::string kVispCube = "/usr/share/visp-images-data/ViSP-images/mbt/cube.cao";

constexpr double kAreaTolM2 = 1e-9;
constexpr int kSamples = 10000;

NavigableArea SidecarHall(const WireframeModel& model) {
  NavigableAreaOptions options;
  options.sidecar_path = kHallSidecar;
  return NavigableArea::FromModel(model, options);
}

WireframeModel FromText(const std::string& text) {
  return WireframeModel::FromCao(ParseCao(text, "mem.cao", nullptr));
}

// Counts the points of a seeded sample of the box where a.Contains(p) != b.Contains(map(p)).
template <typename Map>
int Disagreements(const NavigableArea& a, const NavigableArea& b, const Map& map, int* inside) {
  std::mt19937 rng(42u);
  const Eigen::Vector2d lo = a.BoundsMin().array() - 0.5, hi = a.BoundsMax().array() + 0.5;
  std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y());
  int disagree = 0;
  *inside = 0;
  for (int i = 0; i < kSamples; ++i) {
    const Eigen::Vector2d p(ux(rng), uy(rng));
    const bool in_a = a.Contains(p);
    *inside += in_a ? 1 : 0;
    disagree += in_a != b.Contains(map(p)) ? 1 : 0;
  }
  return disagree;
}

TEST(NavigableArea, HallFromWallsAgreesWithTheHandWrittenArea) {
  const WireframeModel model = WireframeModel::Load(kModels + "/hall.cao");
  const NavigableArea derived = NavigableArea::FromModel(model);
  const NavigableArea sidecar = SidecarHall(model);
  EXPECT_EQ(derived.source(), "walls (15 faces)");
  EXPECT_EQ(sidecar.source(), "sidecar hall.nav.json");
  // The partition, attached to the north wall, is a notch of the outer boundary; the pillars are
  // holes.
  EXPECT_EQ(derived.parts().at(0).outer.vertices.size(), 8u);
  EXPECT_EQ(derived.parts().at(0).holes.size(), 2u);
  EXPECT_NEAR(derived.Area(), 14.0 * 9.0 - 0.2 * 3.5 - 2 * 0.25, kAreaTolM2);
  EXPECT_NEAR(derived.Area(), sidecar.Area(), kAreaTolM2);
  int inside = 0;
  EXPECT_EQ(Disagreements(
                derived, sidecar, [](const Eigen::Vector2d& p) { return p; }, &inside),
            0);
  EXPECT_GT(inside, kSamples / 2);  // the sample is mostly inside, and not all of it
  EXPECT_LT(inside, kSamples);
}

TEST(NavigableArea, TurnedHallFromWallsAgreesWithTheHandWrittenArea) {
  CaoModel cao = ReadCao(kModels + "/hall.cao");
  const Eigen::Rotation2Dd turn(DegToRad(-57.0));
  const Eigen::Vector2d shift(-3.0, 11.0);
  for (Eigen::Vector3d& p : cao.points)
    p.head<2>() = shift + turn * p.head<2>();
  const NavigableArea turned = NavigableArea::FromModel(WireframeModel::FromCao(cao));
  const NavigableArea sidecar = SidecarHall(WireframeModel::Load(kModels + "/hall.cao"));
  EXPECT_NEAR(turned.Area(), sidecar.Area(), 1e-9);
  int inside = 0;
  const auto back = [&](const Eigen::Vector2d& p) {
    return Eigen::Vector2d(turn.inverse() * (p - shift));
  };
  EXPECT_EQ(Disagreements(turned, sidecar, back, &inside), 0);
  EXPECT_GT(inside, 0);
}

TEST(NavigableArea, RoomFromWallsKeepsTheOpenCabinetOutByClearance) {
  const NavigableArea area = NavigableArea::FromModel(WireframeModel::Load(kModels + "/room.cao"));
  EXPECT_EQ(area.source(), "walls (6 faces)");
  // The cabinet's two faces dangle from the north wall: no hole, no spike in the boundary.
  EXPECT_EQ(area.parts().at(0).outer.vertices.size(), 4u);
  EXPECT_TRUE(area.parts().at(0).holes.empty());
  EXPECT_NEAR(area.Area(), 20.0, kAreaTolM2);
  EXPECT_TRUE(area.Contains({2.5, 2.0}));
  EXPECT_FALSE(area.Contains({4.0, 3.6}));  // in the cabinet, within the clearance of its faces
  EXPECT_FALSE(area.Contains({2.5, 0.2}));  // within the clearance of the south wall
}

TEST(NavigableArea, ObjectWithoutEnclosingWallsFallsBackToItsBoundingBox) {
  const WireframeModel cube = WireframeModel::Load(kVispCube);
  const NavigableArea area = NavigableArea::FromModel(cube);
  EXPECT_EQ(area.source(), "bounding box + 2 m (no enclosing walls)");
  ASSERT_EQ(area.parts().at(0).holes.size(), 1u);  // the cube's footprint
  const double side = 0.084;
  EXPECT_NEAR(area.Area(), (side + 4.0) * (side + 4.0) - side * side, kAreaTolM2);
  EXPECT_FALSE(area.Contains({-0.042, 0.042}));
  EXPECT_TRUE(area.Contains({1.0, 1.0}));
  EXPECT_FALSE(area.Contains({2.5, 0.0}));
}

TEST(NavigableArea, ModelWithoutFacesIsItsBoundingBoxGrown) {
  const NavigableArea area =
      NavigableArea::FromModel(FromText("V1\n2\n0 0 0\n1 2 3\n1\n0 1\n0\n0\n0\n0\n"));
  EXPECT_EQ(area.source(), "bounding box + 2 m (no enclosing walls)");
  EXPECT_TRUE(area.parts().at(0).holes.empty());
  EXPECT_NEAR(area.Area(), 5.0 * 6.0, kAreaTolM2);
}

// Faces of a vertical wall from floor point a to b, height h, seen from its left (or both sides).
std::string WallFace(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double h,
                     std::vector<Eigen::Vector3d>* points, bool two_sided) {
  const int base = static_cast<int>(points->size());
  points->push_back({a.x(), a.y(), 0.0});
  points->push_back({b.x(), b.y(), 0.0});
  points->push_back({b.x(), b.y(), h});
  points->push_back({a.x(), a.y(), h});
  // Counter-clockwise seen from the left of a -> b: a, a_top, b_top, b.
  std::string faces = "4 " + std::to_string(base) + " " + std::to_string(base + 3) + " " +
                      std::to_string(base + 2) + " " + std::to_string(base + 1) + "\n";
  if (two_sided) {
    faces += "4 " + std::to_string(base) + " " + std::to_string(base + 1) + " " +
             std::to_string(base + 2) + " " + std::to_string(base + 3) + "\n";
  }
  return faces;
}

TEST(NavigableArea, ClosedNonConvexObstacleBecomesAHole) {
  std::vector<Eigen::Vector3d> points;
  std::string faces;
  const std::vector<Eigen::Vector2d> room = {{0, 0}, {8, 0}, {8, 6}, {0, 6}};
  for (int i = 0; i < 4; ++i)
    faces += WallFace(room[i], room[(i + 1) % 4], 2.5, &points, false);
  // An L-shaped block, faces seen from outside: walk it clockwise so that outside is on the left.
  const std::vector<Eigen::Vector2d> block = {{3, 2}, {3, 4}, {4, 4}, {4, 3}, {5, 3}, {5, 2}};
  for (int i = 0; i < 6; ++i)
    faces += WallFace(block[i], block[(i + 1) % 6], 2.5, &points, false);
  std::string text = "V1\n" + std::to_string(points.size()) + "\n";
  for (const Eigen::Vector3d& p : points) {
    text +=
        std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
  }
  text += "0\n0\n10\n" + faces + "0\n0\n";
  const NavigableArea area = NavigableArea::FromModel(FromText(text));
  EXPECT_EQ(area.source(), "walls (10 faces)");
  ASSERT_EQ(area.parts().at(0).holes.size(), 1u);
  EXPECT_NEAR(area.Area(), 48.0 - 3.0, kAreaTolM2);
  EXPECT_FALSE(area.Contains({3.5, 3.5}));
  EXPECT_TRUE(area.Contains({4.5, 3.5}));  // in the L's notch, 0.5 m from its faces
}

class BadSidecar : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

TEST_P(BadSidecar, IsAnInputErrorNamingTheFile) {
  const auto [name, content] = GetParam();
  const std::string path = ::testing::TempDir() + "linetrack_bad_" + name + ".nav.json";
  std::ofstream(path) << content;
  NavigableAreaOptions options;
  options.sidecar_path = path;
  const WireframeModel model = WireframeModel::Load(kModels + "/room.cao");
  try {
    NavigableArea::FromModel(model, options);
    ADD_FAILURE() << "expected an InputError for " << name;
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
  }
  std::filesystem::remove(path);
}

INSTANTIATE_TEST_SUITE_P(
    Contents, BadSidecar,
    ::testing::Values(std::make_pair("not_json", "outer: [[0, 0], [1, 0], [1, 1]]"),
                      std::make_pair("missing_outer", "{\"holes\": []}"),
                      std::make_pair("nan", "{\"outer\": [[0, 0], [1, 0], [NaN, 1]]}"),
                      std::make_pair("two_points", "{\"outer\": [[0, 0], [1, 0]]}"),
                      std::make_pair("no_area", "{\"outer\": [[0, 0], [1, 1], [2, 2]]}"),
                      std::make_pair("bad_hole",
                                     "{\"outer\": [[0, 0], [4, 0], [4, 4]], "
                                     "\"holes\": [[[1, 1], [\"x\", 1], [1, 2]]]}"),
                      std::make_pair("bad_clearance",
                                     "{\"outer\": [[0, 0], [4, 0], [4, 4]], \"clearance\": -1}")),
    [](const auto& info) { return std::string(info.param.first); });

TEST(NavigableArea, MissingSidecarFileIsAnInputError) {
  NavigableAreaOptions options;
  options.sidecar_path = ::testing::TempDir() + "linetrack_no_such_file.nav.json";
  EXPECT_THROW(NavigableArea::FromModel(WireframeModel::Load(kModels + "/room.cao"), options),
               InputError);
}

}  // namespace
}  // namespace linetrack
