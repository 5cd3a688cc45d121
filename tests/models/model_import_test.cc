// The importer (models/import/): welding and collinear points on exact data, a triangulated room
// back to its six faces, the bundled hall exported as an OBJ triangle mesh in millimetres with y
// up and imported again to the same edges, and the same room written by the test as PLY, STL,
// glTF, DXF and IFC.
#include "models/import/model_import.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/import/import_guards.h"
#include "models/wireframe.h"
#include "tests/support/obj_export.h"

namespace linetrack {
namespace {

constexpr double kPointTolM = 1e-6;
// The round trip writes millimetres with 3 decimals: ends within this of the original (metres).
constexpr double kRoundTripTolM = 1e-5;

const std::string kSource = LINETRACK_SOURCE_DIR;

std::string TempPath(const std::string& name) {
  return ::testing::TempDir() + "linetrack_import_" + name;
}

std::string Write(const std::string& name, const std::string& text) {
  const std::string path = TempPath(name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// A room 4 m x 3 m x 2.5 m: 8 corners, 12 triangles (two per side, wound outward).
ImportMesh Room() {
  ImportMesh mesh;
  for (int k = 0; k < 8; ++k)
    mesh.points.emplace_back(k & 1 ? 4.0 : 0.0, k & 2 ? 3.0 : 0.0, k & 4 ? 2.5 : 0.0);
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    mesh.triangles.push_back({q[0], q[1], q[2]});
    mesh.triangles.push_back({q[0], q[2], q[3]});
  }
  return mesh;
}

// Every edge of `a` has an edge of `b` with the same ends (either way) within `tol`, and the
// counts match.
void ExpectSameEdges(const WireframeModel& a, const WireframeModel& b, double tol) {
  ASSERT_EQ(a.edges().size(), b.edges().size());
  for (const ModelEdge& e : a.edges()) {
    const bool found = std::any_of(b.edges().begin(), b.edges().end(), [&](const ModelEdge& f) {
      return ((e.segment.a - f.segment.a).norm() < tol &&
              (e.segment.b - f.segment.b).norm() < tol) ||
             ((e.segment.a - f.segment.b).norm() < tol && (e.segment.b - f.segment.a).norm() < tol);
    });
    EXPECT_TRUE(found) << "edge " << e.id << " (" << e.name << ") " << e.segment.a.transpose()
                       << " - " << e.segment.b.transpose();
  }
}

// Checks that `cao` is the room of Room(): six faces, twelve edges, its corners.
void ExpectRoom(const CaoModel& cao) {
  EXPECT_EQ(cao.faces.size(), 6u);
  EXPECT_EQ(cao.lines.size(), 0u);
  const WireframeModel model = WireframeModel::FromCao(cao);
  ExpectSameEdges(model, WireframeModel::FromCao(MeshToCao(Room(), {}, "room", nullptr)),
                  kRoundTripTolM);
}

TEST(WeldPoints, MergesWithinTheToleranceOnly) {
  const std::vector<Eigen::Vector3d> points = {
      {0, 0, 0}, {0.0009, 0, 0}, {0.0011, 0, 0}, {5, 5, 5}, {5, 5, 5.0004}};
  EXPECT_EQ(WeldPoints(points, 1e-3), (std::vector<int>{0, 0, 2, 3, 3}));
}

TEST(WithoutCollinear, DropsPointsOnStraightRuns) {
  const std::vector<Eigen::Vector3d> points = {{0, 0, 0}, {1, 0, 0},      {2, 0, 0}, {2, 1, 0},
                                               {2, 2, 0}, {0, 2, 0.0005}, {0, 1, 0}};
  EXPECT_EQ(WithoutCollinear({0, 1, 2, 3, 4, 5, 6}, points, 1e-3), (std::vector<int>{0, 2, 4, 5}));
}

TEST(MeshToCao, TriangulatedRoomGivesItsSixFaces) {
  MeshToCaoSummary summary;
  const CaoModel cao = MeshToCao(Room(), {}, "room", &summary);
  EXPECT_EQ(summary.faces, 6);
  EXPECT_EQ(summary.tessellation_edges, 6);
  EXPECT_EQ(summary.feature_edges, 12);
  EXPECT_EQ(summary.merged_triangles, 12);
  EXPECT_EQ(cao.points.size(), 8u);
  EXPECT_EQ(WireframeModel::FromCao(cao).edges().size(), 12u);
}

TEST(MeshToCao, ThinQuadInFrontOfAWallBecomesLinesOnIt) {
  ImportMesh mesh = Room();
  // A door leaf 1 cm in front of the wall y = 0 (inside the room), 0.9 m x 2 m.
  const int n = static_cast<int>(mesh.points.size());
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(1.0, 0.01, 0.0), Eigen::Vector3d(1.9, 0.01, 0.0),
        Eigen::Vector3d(1.9, 0.01, 2.0), Eigen::Vector3d(1.0, 0.01, 2.0)})
    mesh.points.push_back(p);
  mesh.triangles.push_back({n, n + 1, n + 2});
  mesh.triangles.push_back({n, n + 2, n + 3});
  MeshToCaoSummary summary;
  const CaoModel cao = MeshToCao(mesh, {}, "room with door", &summary);
  EXPECT_EQ(summary.openings, 1);
  EXPECT_EQ(cao.faces.size(), 6u);
  ASSERT_EQ(cao.lines.size(), 4u);
  for (const std::array<int, 2>& line : cao.lines) {
    for (int end : line)
      EXPECT_NEAR(cao.points[end].y(), 0.0, kPointTolM) << "on the wall y = 0";
  }
}

TEST(MeshToCao, CurvedSurfaceKeepsItsOutlineNotItsFacets) {
  // A round pillar, radius 0.2 m, 2.5 m high: 24 side facets (15 degrees apart) and two caps.
  constexpr int kSides = 24;
  ImportMesh mesh;
  for (int k = 0; k < kSides; ++k) {
    const double a = 2.0 * kPi * k / kSides;
    mesh.points.emplace_back(0.2 * std::cos(a), 0.2 * std::sin(a), 0.0);
    mesh.points.emplace_back(0.2 * std::cos(a), 0.2 * std::sin(a), 2.5);
  }
  for (int k = 0; k < kSides; ++k) {
    const int a = 2 * k, b = 2 * ((k + 1) % kSides);
    mesh.triangles.push_back({a, b, b + 1});
    mesh.triangles.push_back({a, b + 1, a + 1});
    if (k > 0 && k + 1 < kSides) {
      mesh.triangles.push_back({0, b, a});          // bottom cap, a fan
      mesh.triangles.push_back({1, a + 1, b + 1});  // top cap
    }
  }
  MeshToCaoSummary summary;
  const CaoModel cao = MeshToCao(mesh, {}, "pillar", &summary);
  EXPECT_EQ(summary.curved_facets, kSides);
  EXPECT_EQ(cao.faces.size(), 2u);  // the caps
  EXPECT_EQ(cao.lines.size(), 0u);  // the rims are the caps' edges; no vertical facet edge
  const WireframeModel model = WireframeModel::FromCao(cao);
  EXPECT_EQ(model.edges().size(), 2u * kSides);
  EXPECT_TRUE(std::none_of(model.edges().begin(), model.edges().end(),
                           [](const ModelEdge& e) { return e.vertical; }));
}

TEST(ModelImport, HallRoundTripThroughObjInMillimetresYUp) {
  const std::string hall_path = kSource + "/models/hall.cao";
  const CaoModel hall = ReadCao(hall_path);
  const std::string obj = Write("hall.obj", test_support::ObjMillimetresYUp(hall));
  ModelImportOptions options;
  options.metres_per_unit = 1e-3;
  const ImportedModel imported = ImportModel(obj, options);
  EXPECT_EQ(imported.up, UpAxis::kY);  // the OBJ default
  EXPECT_EQ(imported.cao.faces.size(), hall.faces.size());
  EXPECT_TRUE(imported.warnings.empty());
  ExpectSameEdges(WireframeModel::Load(hall_path), WireframeModel::FromCao(imported.cao),
                  kRoundTripTolM);
  // Read as metres, the hall is 14 km wide: the importer says so.
  const ImportedModel as_metres = ImportModel(obj, ModelImportOptions());
  ASSERT_EQ(as_metres.warnings.size(), 1u);
  EXPECT_NE(as_metres.warnings.front().find("millimetres"), std::string::npos);
}

TEST(ModelImport, RoomAsPly) {
  const ImportMesh room = Room();
  std::ostringstream ply;
  ply << "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
         "property float z\nelement face 12\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Eigen::Vector3d& p : room.points)
    ply << p.x() << " " << p.y() << " " << p.z() << "\n";
  for (const auto& t : room.triangles)
    ply << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  ExpectRoom(ImportModel(Write("room.ply", ply.str()), ModelImportOptions()).cao);
}

TEST(ModelImport, RoomAsStlInCentimetres) {
  const ImportMesh room = Room();
  std::ostringstream stl;
  stl << "solid room\n";
  for (const auto& t : room.triangles) {
    stl << "facet normal 0 0 0\n outer loop\n";
    for (int k : t)
      stl << "  vertex " << 100 * room.points[k].x() << " " << 100 * room.points[k].y() << " "
          << 100 * room.points[k].z() << "\n";
    stl << " endloop\nendfacet\n";
  }
  stl << "endsolid room\n";
  ModelImportOptions options;
  options.metres_per_unit = 0.01;
  ExpectRoom(ImportModel(Write("room.stl", stl.str()), options).cao);
}

// RFC 4648 base64 of `bytes`, for a glTF data URI.
std::string Base64(const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    unsigned n = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) n |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) n |= static_cast<unsigned char>(bytes[i + 2]);
    const size_t left = bytes.size() - i;
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += left > 1 ? kAlphabet[(n >> 6) & 63] : '=';
    out += left > 2 ? kAlphabet[n & 63] : '=';
  }
  return out;
}

TEST(ModelImport, RoomAsGltfYUpInMetres) {
  const ImportMesh room = Room();
  std::string buffer;
  for (const Eigen::Vector3d& p : room.points) {
    // glTF: y up.
    for (const float c :
         {static_cast<float>(p.x()), static_cast<float>(p.z()), static_cast<float>(-p.y())})
      buffer.append(reinterpret_cast<const char*>(&c), sizeof(c));
  }
  for (const auto& t : room.triangles) {
    for (int k : t) {
      const uint16_t i = static_cast<uint16_t>(k);
      buffer.append(reinterpret_cast<const char*>(&i), sizeof(i));
    }
  }
  std::ostringstream gltf;
  gltf << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
       << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
       << R"("buffers":[{"byteLength":)" << buffer.size()
       << R"(,"uri":"data:application/octet-stream;base64,)" << Base64(buffer) << R"("}],)"
       << R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":96},)"
       << R"({"buffer":0,"byteOffset":96,"byteLength":72}],)"
       << R"("accessors":[{"bufferView":0,"componentType":5126,"count":8,"type":"VEC3",)"
       << R"("min":[0,0,-3],"max":[4,2.5,0]},)"
       << R"({"bufferView":1,"componentType":5123,"count":36,"type":"SCALAR"}]})";
  ModelImportOptions options;
  options.metres_per_unit = 1e-3;  // ignored: glTF is in metres
  const ImportedModel model = ImportModel(Write("room.gltf", gltf.str()), options);
  EXPECT_EQ(model.up, UpAxis::kY);
  EXPECT_EQ(model.metres_per_unit, 1.0);
  ExpectRoom(model.cao);
}

TEST(ModelImport, RoomAsDxfFaces) {
  const ImportMesh room = Room();
  std::ostringstream dxf;
  dxf << "0\nSECTION\n2\nENTITIES\n";
  for (const auto& t : room.triangles) {
    dxf << "0\n3DFACE\n8\n0\n";
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d& p = room.points[t[std::min(k, 2)]];
      dxf << 10 + k << "\n"
          << p.x() << "\n"
          << 20 + k << "\n"
          << p.y() << "\n"
          << 30 + k << "\n"
          << p.z() << "\n";
    }
  }
  dxf << "0\nENDSEC\n0\nEOF\n";
  ExpectRoom(ImportModel(Write("room.dxf", dxf.str()), ModelImportOptions()).cao);
}

// A minimal IFC-SPF file: one wall, a 4 m x 0.2 m rectangle extruded 2.5 m, in millimetres.
constexpr const char* kWallIfc = R"(ISO-10303-21;
HEADER;
FILE_DESCRIPTION(('ViewDefinition [CoordinationView]'),'2;1');
FILE_NAME('wall.ifc','2026-11-27T00:00:00',(''),(''),'','','');
FILE_SCHEMA(('IFC2X3'));
ENDSEC;
DATA;
#2=IFCPERSON($,'Doe','John',$,$,$,$,$);
#3=IFCORGANIZATION($,'Lab',$,$,$);
#4=IFCPERSONANDORGANIZATION(#2,#3,$);
#5=IFCAPPLICATION(#3,'1','linetrack test','lt');
#6=IFCOWNERHISTORY(#4,#5,$,.ADDED.,$,$,$,0);
#1=IFCPROJECT('0001',#6,'Project',$,$,$,$,(#20),#10);
#10=IFCUNITASSIGNMENT((#11));
#11=IFCSIUNIT(*,.LENGTHUNIT.,.MILLI.,.METRE.);
#20=IFCGEOMETRICREPRESENTATIONCONTEXT($,'Model',3,1.E-05,#21,$);
#21=IFCAXIS2PLACEMENT3D(#22,$,$);
#22=IFCCARTESIANPOINT((0.,0.,0.));
#30=IFCSITE('0002',#6,'Site',$,$,#31,$,$,.ELEMENT.,$,$,$,$,$);
#31=IFCLOCALPLACEMENT($,#21);
#32=IFCRELAGGREGATES('0003',#6,$,$,#1,(#30));
#40=IFCBUILDING('0004',#6,'Building',$,$,#41,$,$,.ELEMENT.,$,$,$);
#41=IFCLOCALPLACEMENT(#31,#21);
#42=IFCRELAGGREGATES('0005',#6,$,$,#30,(#40));
#50=IFCBUILDINGSTOREY('0006',#6,'Ground',$,$,#51,$,$,.ELEMENT.,0.);
#51=IFCLOCALPLACEMENT(#41,#21);
#52=IFCRELAGGREGATES('0007',#6,$,$,#40,(#50));
#60=IFCWALLSTANDARDCASE('0008',#6,'Wall',$,$,#61,#70,$);
#61=IFCLOCALPLACEMENT(#51,#21);
#70=IFCPRODUCTDEFINITIONSHAPE($,$,(#71));
#71=IFCSHAPEREPRESENTATION(#20,'Body','SweptSolid',(#72));
#72=IFCEXTRUDEDAREASOLID(#73,#76,#79,2500.);
#73=IFCRECTANGLEPROFILEDEF(.AREA.,$,#74,4000.,200.);
#74=IFCAXIS2PLACEMENT2D(#75,$);
#75=IFCCARTESIANPOINT((2000.,100.));
#76=IFCAXIS2PLACEMENT3D(#22,$,$);
#79=IFCDIRECTION((0.,0.,1.));
#80=IFCRELCONTAINEDINSPATIALSTRUCTURE('0009',#6,$,$,(#60),#50);
ENDSEC;
END-ISO-10303-21;
)";

TEST(ModelImport, IfcExtrudedWallInItsOwnUnit) {
  ModelImportOptions options;
  options.up = UpAxis::kZ;  // ignored: Assimp reads IFC's axes
  const ImportedModel model = ImportModel(Write("wall.ifc", kWallIfc), options);
  EXPECT_EQ(model.metres_per_unit, 1.0);
  EXPECT_EQ(model.cao.faces.size(), 6u);
  Eigen::Vector3d lo = model.cao.points.front(), hi = lo;
  for (const Eigen::Vector3d& p : model.cao.points)
    lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  EXPECT_LT((lo - Eigen::Vector3d(0.0, 0.0, 0.0)).norm(), kRoundTripTolM) << lo.transpose();
  EXPECT_LT((hi - Eigen::Vector3d(4.0, 0.2, 2.5)).norm(), kRoundTripTolM) << hi.transpose();
  EXPECT_EQ(WireframeModel::FromCao(model.cao).edges().size(), 12u);
}

TEST(ModelImport, BadFileIsAnInputErrorNamingIt) {
  const std::string path = Write("garbage.obj", "this is not a model\n");
  try {
    ImportModel(path, ModelImportOptions());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_THROW(ImportModel(TempPath("missing.obj"), ModelImportOptions()), InputError);
}

// The error of ImportModel on `path`, or "" when it imports.
std::string ImportError(const std::string& path) {
  try {
    ImportModel(path, ModelImportOptions());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Assimp 5.2.5 does not return on the first header; the others claim more than the file holds,
// break the grammar, or (without the .ply extension) are found by their magic.
TEST(ModelImport, MalformedPlyHeadersAreRefusedBeforeAssimp) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\n";
  const std::string body = "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::string face = "property list uchar int vertex_indices\n";
  for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
           {"extra.ply", head + "element face 1 1 2\n" + face + body},
           {"count.ply", head + "element face 99999999\n" + face + body},
           {"binary.ply",
            "ply\nformat binary_little_endian 1.0\nelement vertex 1000000\nproperty float x\n"
            "end_header\n0000"},
           {"type.ply", head + "element face 1\nproperty list uchar quad idx\n" + body},
           {"orphan.ply", "ply\nformat ascii 1.0\nproperty float x\n" + body},
           {"noend.ply", head},
           {"magic.obj", head + "element face 1 1 2\n" + face + body}}) {
    const std::string path = Write(name, text);
    const std::string error = ImportError(path);
    EXPECT_NE(error.find(path), std::string::npos) << name << ": " << error;
    EXPECT_NE(error.find("PLY header"), std::string::npos) << name << ": " << error;
  }
  EXPECT_EQ(ImportError(Write("one.ply", head + "element face 1\n" + face + body)), "");
}

TEST(CheckPlyText, CountsMustFitTheFile) {
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
      "property double y\nend_header\n";
  // Two records of 4 + 8 bytes.
  EXPECT_NO_THROW(CheckPlyText(header, header.size() + 24, "a.ply"));
  EXPECT_THROW(CheckPlyText(header, header.size() + 23, "a.ply"), InputError);
}

TEST(MeshToCao, NonFiniteOrFarPointsAndBadIndicesAreInputErrors) {
  ImportMesh mesh = Room();
  mesh.points[0].x() = std::nan("");
  EXPECT_THROW(MeshToCao(mesh, MeshToCaoOptions(), "nan.obj", nullptr), InputError);
  mesh.points[0].x() = 1e300;
  EXPECT_THROW(MeshToCao(mesh, MeshToCaoOptions(), "far.obj", nullptr), InputError);
  mesh = Room();
  mesh.triangles[0][1] = static_cast<int>(mesh.points.size());
  EXPECT_THROW(MeshToCao(mesh, MeshToCaoOptions(), "index.obj", nullptr), InputError);
}

}  // namespace
}  // namespace linetrack
