// The model checks, one small model written here per finding (and the bundled models with none):
// no vertical edges, no enclosure, a gap in the walls, a stray 3D line, degenerate, non-planar and
// self-intersecting faces, millimetres, georeferenced coordinates, edges too short to be seen.
#include "models/model_checks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <sstream>

#include "models/cao_reader.h"
#include "models/wireframe.h"

namespace linetrack {
namespace {

const std::string kModels = std::string(LINETRACK_SOURCE_DIR) + "/models";

// A .cao text of `points`, `lines` (point index pairs) and `faces` (point index loops).
std::string Cao(const std::vector<Eigen::Vector3d>& points,
                const std::vector<std::array<int, 2>>& lines,
                const std::vector<std::vector<int>>& faces) {
  std::ostringstream out;
  out.precision(17);
  out << "V1\n" << points.size() << "\n";
  for (const Eigen::Vector3d& p : points)
    out << p.x() << " " << p.y() << " " << p.z() << "\n";
  out << lines.size() << "\n";
  for (const auto& l : lines)
    out << l[0] << " " << l[1] << "\n";
  out << "0\n" << faces.size() << "\n";
  for (const auto& f : faces) {
    out << f.size();
    for (int i : f)
      out << " " << i;
    out << "\n";
  }
  out << "0\n0\n";
  return out.str();
}

// A room [0, w] x [0, d] x [0, h] scaled by `scale` and moved by `shift`: four walls facing in,
// `walls` of them (a missing wall leaves a gap), and the corner points.
struct Room {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::vector<int>> faces;
};

Room MakeRoom(int walls = 4, double scale = 1.0,
              const Eigen::Vector3d& shift = Eigen::Vector3d::Zero()) {
  const double w = 6.0, d = 4.0, h = 2.5;
  Room room;
  const std::vector<Eigen::Vector2d> c = {{0, 0}, {w, 0}, {w, d}, {0, d}};
  for (const Eigen::Vector2d& p : c) {
    room.points.push_back(scale * Eigen::Vector3d(p.x(), p.y(), 0.0) + shift);
    room.points.push_back(scale * Eigen::Vector3d(p.x(), p.y(), h) + shift);
  }
  for (int i = 0; i < walls; ++i) {
    const int a = 2 * i, b = 2 * ((i + 1) % 4);
    room.faces.push_back({a, a + 1, b + 1, b});
  }
  return room;
}

std::vector<FindingKind> Kinds(const std::string& text) {
  const WireframeModel model = WireframeModel::FromCao(ParseCao(text, "test.cao", nullptr));
  std::vector<FindingKind> kinds;
  for (const ModelFinding& f : CheckModel(model)) {
    EXPECT_EQ(f.message.rfind("test.cao: ", 0), 0u) << f.message;
    kinds.push_back(f.kind);
  }
  return kinds;
}

bool Has(const std::vector<FindingKind>& kinds, FindingKind kind) {
  return std::find(kinds.begin(), kinds.end(), kind) != kinds.end();
}

TEST(ModelChecks, BundledModelsHaveNoFinding) {
  for (const char* name : {"hall.cao", "room.cao"}) {
    const std::vector<ModelFinding> findings =
        CheckModel(WireframeModel::Load(kModels + "/" + name));
    EXPECT_TRUE(findings.empty()) << name << ": " << findings.front().message;
  }
}

TEST(ModelChecks, AClosedRoomHasNoFinding) {
  const Room room = MakeRoom();
  EXPECT_TRUE(Kinds(Cao(room.points, {}, room.faces)).empty());
}

TEST(ModelChecks, NoVerticalEdges) {
  // A floor and a table top: horizontal faces only.
  const std::vector<Eigen::Vector3d> points = {{0, 0, 0},   {4, 0, 0},   {4, 3, 0},   {0, 3, 0},
                                               {1, 1, 0.7}, {2, 1, 0.7}, {2, 2, 0.7}, {1, 2, 0.7}};
  const std::vector<FindingKind> kinds = Kinds(Cao(points, {}, {{0, 1, 2, 3}, {4, 5, 6, 7}}));
  EXPECT_TRUE(Has(kinds, FindingKind::kNoVerticalEdges));
  EXPECT_TRUE(Has(kinds, FindingKind::kNoFreeSpace));
}

TEST(ModelChecks, AMissingWallLeavesAGapAndNoFreeSpace) {
  const Room room = MakeRoom(3);
  const std::vector<FindingKind> kinds = Kinds(Cao(room.points, {}, room.faces));
  EXPECT_TRUE(Has(kinds, FindingKind::kNoFreeSpace));
  EXPECT_TRUE(Has(kinds, FindingKind::kOpenWalls));
}

TEST(ModelChecks, ADoorLineOffItsWallIsStray) {
  Room room = MakeRoom();
  const int n = static_cast<int>(room.points.size());
  // A door jamb on the south wall (y = 0), and the same 0.3 m into the room.
  room.points.push_back({2.0, 0.0, 0.0});
  room.points.push_back({2.0, 0.0, 2.1});
  room.points.push_back({3.0, 0.3, 0.0});
  room.points.push_back({3.0, 0.3, 2.1});
  const std::string on_wall = Cao(room.points, {{n, n + 1}}, room.faces);
  EXPECT_FALSE(Has(Kinds(on_wall), FindingKind::kStrayLine));
  const std::string off_wall = Cao(room.points, {{n, n + 1}, {n + 2, n + 3}}, room.faces);
  EXPECT_TRUE(Has(Kinds(off_wall), FindingKind::kStrayLine));
}

TEST(ModelChecks, DegenerateNonPlanarAndSelfIntersectingFaces) {
  Room room = MakeRoom();
  const int n = static_cast<int>(room.points.size());
  // Three collinear points; a bent quad; a bow tie, all on the room's side walls.
  room.points.insert(room.points.end(), {{1, 0, 0.5}, {2, 0, 0.5}, {3, 0, 0.5}});
  room.points.insert(room.points.end(), {{6, 1, 0.5}, {6, 2, 0.5}, {5.9, 2, 1.5}, {6, 1, 1.5}});
  room.points.insert(room.points.end(), {{1, 4, 0.5}, {3, 4, 1.5}, {3, 4, 0.5}, {1, 4, 2.5}});
  std::vector<std::vector<int>> faces = room.faces;
  faces.push_back({n, n + 1, n + 2});
  faces.push_back({n + 3, n + 4, n + 5, n + 6});
  faces.push_back({n + 7, n + 8, n + 9, n + 10});
  const std::vector<FindingKind> kinds = Kinds(Cao(room.points, {}, faces));
  EXPECT_TRUE(Has(kinds, FindingKind::kDegenerateFace));
  EXPECT_TRUE(Has(kinds, FindingKind::kNonPlanarFace));
  EXPECT_TRUE(Has(kinds, FindingKind::kSelfIntersectingFace));
}

TEST(ModelChecks, MillimetresAreAnImplausibleExtent) {
  const Room room = MakeRoom(4, 1000.0);
  const std::vector<FindingKind> kinds = Kinds(Cao(room.points, {}, room.faces));
  EXPECT_TRUE(Has(kinds, FindingKind::kImplausibleExtent));
  EXPECT_FALSE(Has(kinds, FindingKind::kShortEdges));
}

TEST(ModelChecks, GeoreferencedCoordinatesAreFarFromTheOrigin) {
  const Room room = MakeRoom(4, 1.0, {432000.0, 5412000.0, 0.0});
  const std::vector<FindingKind> kinds = Kinds(Cao(room.points, {}, room.faces));
  EXPECT_TRUE(Has(kinds, FindingKind::kFarFromOrigin));
  EXPECT_FALSE(Has(kinds, FindingKind::kImplausibleExtent));
}

TEST(ModelChecks, EdgesTooShortForTheMatcher) {
  Room room = MakeRoom();
  const int n = static_cast<int>(room.points.size());
  // A 2 cm mark on the south wall: 7 px at 3 m with f = 1000 px.
  room.points.push_back({3.0, 0.0, 1.0});
  room.points.push_back({3.02, 0.0, 1.0});
  const std::vector<FindingKind> kinds = Kinds(Cao(room.points, {{n, n + 1}}, room.faces));
  EXPECT_TRUE(Has(kinds, FindingKind::kShortEdges));
  EXPECT_FALSE(Has(kinds, FindingKind::kStrayLine));
}

TEST(ModelChecks, GeometryHelpers) {
  ModelFace square;
  square.corners = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  square.normal = Eigen::Vector3d::UnitZ();
  square.offset = 0.0;
  EXPECT_NEAR(DistanceToFace(square, {0.5, 0.5, 0.3}), 0.3, 1e-12);
  EXPECT_NEAR(DistanceToFace(square, {2.0, 0.5, 0.0}), 1.0, 1e-12);
  EXPECT_FALSE(SelfIntersecting(square));
  ModelFace bow = square;
  bow.corners = {{0, 0, 0}, {1, 1, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_TRUE(SelfIntersecting(bow));
}

}  // namespace
}  // namespace linetrack
