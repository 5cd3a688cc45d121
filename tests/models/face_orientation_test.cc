// Face orientation on load: the bundled models with all or a seeded subset of their faces reversed
// come out exactly as written; small models written here (floors and ceilings, two rooms with
// thick walls and a door, a box object) get their faces turned to the free space.
#include "models/face_orientation.h"

#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "models/cao_reader.h"
#include "models/cao_writer.h"
#include "models/free_space.h"
#include "models/wireframe.h"
#include "tests/support/reversed_faces.h"

namespace linetrack {
namespace {

const std::string kModels = std::string(LINETRACK_SOURCE_DIR) + "/models";
const std::string kVispCube = "/usr/share/visp-images-data/ViSP-images/mbt/cube.cao";

int CountReversed(const CaoModel& a, const CaoModel& b) {
  int n = 0;
  for (size_t f = 0; f < a.faces.size(); ++f)
    n += a.faces[f] != b.faces[f] ? 1 : 0;
  return n;
}

// Faces (points, normals), edges (ids, ends, flags) identical.
void ExpectSameModel(const WireframeModel& a, const WireframeModel& b) {
  ASSERT_EQ(a.faces().size(), b.faces().size());
  for (size_t f = 0; f < a.faces().size(); ++f) {
    EXPECT_EQ(a.faces()[f].vertices, b.faces()[f].vertices) << "face " << f;
    EXPECT_EQ(a.faces()[f].normal, b.faces()[f].normal) << "face " << f;
    EXPECT_EQ(a.faces()[f].offset, b.faces()[f].offset) << "face " << f;
    EXPECT_EQ(a.faces()[f].two_sided, b.faces()[f].two_sided) << "face " << f;
  }
  ASSERT_EQ(a.edges().size(), b.edges().size());
  for (size_t e = 0; e < a.edges().size(); ++e) {
    EXPECT_EQ(a.edges()[e].v0, b.edges()[e].v0) << "edge " << e;
    EXPECT_EQ(a.edges()[e].v1, b.edges()[e].v1) << "edge " << e;
    EXPECT_EQ(a.edges()[e].face, b.edges()[e].face) << "edge " << e;
  }
}

class BundledModel : public ::testing::TestWithParam<const char*> {};

TEST_P(BundledModel, IsWrittenFacingItsFreeSpace) {
  const WireframeModel model = WireframeModel::Load(kModels + "/" + GetParam());
  EXPECT_TRUE(model.oriented());
  for (const ModelFace& face : model.faces())
    EXPECT_FALSE(face.flipped);
  EXPECT_TRUE(model.orientation_summary().empty()) << model.orientation_summary().front();
}

TEST_P(BundledModel, AllFacesReversedComeBackAsWritten) {
  const CaoModel cao = ReadCao(kModels + "/" + GetParam());
  const WireframeModel original = WireframeModel::FromCao(cao);
  const CaoModel reversed = test_support::ReversedFaces(cao, 1.0, 0u);
  const WireframeModel turned = WireframeModel::FromCao(reversed);
  ExpectSameModel(original, turned);
  int flipped = 0;
  for (const ModelFace& face : turned.faces())
    flipped += face.flipped ? 1 : 0;
  EXPECT_EQ(flipped, static_cast<int>(cao.faces.size()));
  // ViSP is handed the faces as the original file writes them.
  EXPECT_EQ(CaoText(OrientedCao(reversed, turned), "t"), CaoText(OrientedCao(cao, original), "t"));
}

TEST_P(BundledModel, SeededSubsetsReversedComeBackAsWritten) {
  const CaoModel cao = ReadCao(kModels + "/" + GetParam());
  const WireframeModel original = WireframeModel::FromCao(cao);
  for (unsigned seed = 1; seed <= 5; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const CaoModel reversed = test_support::ReversedFaces(cao, 0.5, seed);
    ASSERT_GT(CountReversed(cao, reversed), 0);
    ExpectSameModel(original, WireframeModel::FromCao(reversed));
  }
}

INSTANTIATE_TEST_SUITE_P(Models, BundledModel, ::testing::Values("hall.cao", "room.cao"),
                         [](const auto& info) {
                           std::string name = info.param;
                           return name.substr(0, name.find('.'));
                         });

TEST(FaceOrientation, HallReversedSaysWhatItTurned) {
  const WireframeModel turned =
      WireframeModel::FromCao(test_support::ReversedFaces(ReadCao(kModels + "/hall.cao"), 1.0, 0u));
  // Four room walls and the partition's three faces (a wall too thin to stand in), the two
  // pillars' eight faces.
  const std::vector<std::string> expected = {"7 wall faces turned to face the room",
                                             "8 obstacle faces turned outward"};
  EXPECT_EQ(turned.orientation_summary(), expected);
}

TEST(FaceOrientation, ObjectSeenFromOutsideIsLeftAsWritten) {
  const CaoModel cao = ReadCao(kVispCube);
  const WireframeModel cube = WireframeModel::FromCao(test_support::ReversedFaces(cao, 1.0, 0u));
  EXPECT_FALSE(cube.oriented());
  for (const ModelFace& face : cube.faces())
    EXPECT_FALSE(face.flipped);
}

// A .cao text of faces given by their corners (each face's order as listed).
std::string CaoOfFaces(const std::vector<std::vector<Eigen::Vector3d>>& faces) {
  std::ostringstream points, loops;
  int n = 0;
  for (const auto& face : faces) {
    loops << face.size();
    for (const Eigen::Vector3d& c : face) {
      points << c.x() << " " << c.y() << " " << c.z() << "\n";
      loops << " " << n++;
    }
    loops << "\n";
  }
  return "V1\n" + std::to_string(n) + "\n" + points.str() + "0\n0\n" +
         std::to_string(faces.size()) + "\n" + loops.str() + "0\n0\n";
}

// The vertical rectangle over floor segment a -> b from z0 to z1, its normal on the right of
// a -> b (seen from above).
std::vector<Eigen::Vector3d> Wall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z0,
                                  double z1) {
  return {{a.x(), a.y(), z0}, {b.x(), b.y(), z0}, {b.x(), b.y(), z1}, {a.x(), a.y(), z1}};
}

// The horizontal rectangle [x0, x1] x [y0, y1] at z, normal up.
std::vector<Eigen::Vector3d> Slab(double x0, double y0, double x1, double y1, double z) {
  return {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}};
}

TEST(FaceOrientation, FloorFacesUpAndCeilingDown) {
  // A 6 x 4 x 3 m room, walls facing out (right of counter-clockwise), floor down, ceiling up:
  // everything written the wrong way.
  const std::vector<Eigen::Vector2d> c = {{0, 0}, {6, 0}, {6, 4}, {0, 4}};
  std::vector<std::vector<Eigen::Vector3d>> faces;
  for (int i = 0; i < 4; ++i)
    faces.push_back(Wall(c[i], c[(i + 1) % 4], 0.0, 3.0));
  std::vector<Eigen::Vector3d> floor = Slab(0, 0, 6, 4, 0.0), ceiling = Slab(0, 0, 6, 4, 3.0);
  std::reverse(floor.begin(), floor.end());
  faces.push_back(floor);
  faces.push_back(ceiling);
  const WireframeModel model = WireframeModel::FromCao(ParseCao(CaoOfFaces(faces), "m", nullptr));
  for (int i = 0; i < 4; ++i) {
    const ModelFace& wall = model.faces()[i];
    const Eigen::Vector2d inward = Eigen::Vector2d(3.0, 2.0) - wall.corners[0].head<2>();
    EXPECT_GT(wall.normal.head<2>().dot(inward), 0.0) << "wall " << i;
  }
  EXPECT_GT(model.faces()[4].normal.z(), 0.0);
  EXPECT_LT(model.faces()[5].normal.z(), 0.0);
  const std::vector<std::string> expected = {"4 wall faces turned to face the room",
                                             "1 floor face turned up",
                                             "1 ceiling face turned down"};
  EXPECT_EQ(model.orientation_summary(), expected);
}

TEST(FaceOrientation, ThickWallsFaceTheirRoomsAndTheFacadeFacesOut) {
  // Two rooms 4 x 4 m side by side, walls 0.2 m thick, a 0.9 m door through the middle wall,
  // a 3 m storey. Every face is written with its normal on the right of its floor segment: inner
  // faces walked counter-clockwise face out of their room (wrong), the facade walked
  // counter-clockwise faces out (right).
  const double h = 3.0, t = 0.2;
  std::vector<std::vector<Eigen::Vector3d>> faces;
  auto loop = [&](const std::vector<Eigen::Vector2d>& ring) {
    for (size_t i = 0; i < ring.size(); ++i)
      faces.push_back(Wall(ring[i], ring[(i + 1) % ring.size()], 0.0, h));
  };
  loop({{0, 0}, {8.4, 0}, {8.4, 4.4}, {0, 4.4}});  // facade
  // Room A [0.2, 4.2] x [0.2, 4.2] and room B [4.4, 8.2] x [0.2, 4.2]; the door y in [1.8, 2.7].
  loop({{t, t},
        {4.2, t},
        {4.2, 1.8},
        {4.4, 1.8},
        {4.4, t},
        {8.2, t},
        {8.2, 4.2},
        {4.4, 4.2},
        {4.4, 2.7},
        {4.2, 2.7},
        {4.2, 4.2},
        {t, 4.2}});
  const WireframeModel model = WireframeModel::FromCao(ParseCao(CaoOfFaces(faces), "m", nullptr));
  for (size_t f = 0; f < model.faces().size(); ++f) {
    const ModelFace& face = model.faces()[f];
    // Facade faces point away from the building's centre; inner faces toward the free space.
    const Eigen::Vector2d mid = 0.5 * (face.corners[0] + face.corners[2]).head<2>();
    const Eigen::Vector2d probe = mid + 0.05 * face.normal.head<2>();
    const bool in_building = probe.x() > 0 && probe.x() < 8.4 && probe.y() > 0 && probe.y() < 4.4;
    const bool in_wall =
        !(probe.x() > t && probe.x() < 8.2 && probe.y() > t && probe.y() < 4.2) ||
        (probe.x() > 4.2 && probe.x() < 4.4 && (probe.y() < 1.8 || probe.y() > 2.7));
    if (f < 4) {
      EXPECT_FALSE(in_building) << "facade face " << f;
    } else {
      EXPECT_TRUE(in_building && !in_wall) << "inner face " << f;
    }
  }
}

}  // namespace
}  // namespace linetrack
