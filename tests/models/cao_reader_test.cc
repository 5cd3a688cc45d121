// The .cao reader on ViSP's own sample models and on hand-written text.
#include "models/cao_reader.h"

#include <gtest/gtest.h>

#include "models/errors.h"
#include "models/wireframe.h"

namespace linetrack {
namespace {

const std::string kVispImages = "/usr/share/visp-images-data/ViSP-images";

TEST(CaoReader, ReadsViSPCube) {
  const CaoModel cao = ReadCao(kVispImages + "/mbt/cube.cao");
  EXPECT_EQ(cao.points.size(), 8u);
  EXPECT_EQ(cao.lines.size(), 0u);
  ASSERT_EQ(cao.faces.size(), 6u);
  EXPECT_EQ(cao.faces[0], (std::vector<int>{0, 4, 5, 1}));
  const WireframeModel model = WireframeModel::FromCao(cao);
  EXPECT_EQ(model.edges().size(), 12u);  // a cube has 12 edges, each shared by two faces
  EXPECT_EQ(model.NumVerticalEdges(), 4);
  // ViSP's faces are counter-clockwise seen from outside: face 0 (y = 0) faces -y.
  EXPECT_NEAR(model.faces()[0].normal.y(), -1.0, 1e-12);
}

TEST(CaoReader, ResolvesIncludesRelativeToTheFile) {
  const CaoModel cao = ReadCao(kVispImages + "/mbt-depth/Castle-simu/Models/chateau.cao");
  EXPECT_EQ(cao.files.size(), 3u);
  EXPECT_FALSE(cao.points.empty());
}

TEST(CaoReader, EdgesAreLinesThenFaceEdgesDeduplicated) {
  const std::string text =
      "V1\n4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
      "1\n2 0 name=\"diag\"\n"  // a 3D line that is not a face edge
      "0\n"
      "2\n3 0 1 2\n3 0 2 3\n"  // two triangles sharing the diagonal 0-2
      "0\n0\n";
  const WireframeModel model = WireframeModel::FromCao(ParseCao(text, "mem.cao", nullptr));
  ASSERT_EQ(model.edges().size(), 5u);
  EXPECT_TRUE(model.edges()[0].from_line);
  EXPECT_EQ(std::min(model.edges()[0].v0, model.edges()[0].v1), 0);
  EXPECT_EQ(std::max(model.edges()[0].v0, model.edges()[0].v1), 2);
  EXPECT_EQ(model.edges()[1].face, 0);
  EXPECT_EQ(model.edges()[4].face, 1);
}

TEST(CaoReader, EdgesAreNamedAfterTheirLineOrTheirFaces) {
  const std::string text =
      "V1\n5\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n"
      "2\n0 4 name=\"north door jamb\" useLod=true\n1 2\n"  // quoted, with spaces; unnamed
      "0\n"
      "2\n3 0 1 2 name=floor_a\n3 0 2 3 name=\"floor_b\"\n"  // sharing the diagonal 0-2
      "0\n0\n";
  const CaoModel cao = ParseCao(text, "mem.cao", nullptr);
  EXPECT_EQ(cao.line_names, (std::vector<std::string>{"north door jamb", ""}));
  EXPECT_EQ(cao.face_names, (std::vector<std::string>{"floor_a", "floor_b"}));
  const WireframeModel model = WireframeModel::FromCao(cao);
  ASSERT_EQ(model.edges().size(), 6u);
  EXPECT_EQ(model.edges()[0].name, "north door jamb");  // the line's own name
  EXPECT_EQ(model.edges()[1].name, "floor_a");          // an unnamed line on face floor_a
  EXPECT_EQ(model.edges()[2].name, "floor_a");          // 0-1
  EXPECT_EQ(model.edges()[3].name, "floor_a/floor_b");  // 2-0, the shared diagonal
  EXPECT_EQ(model.edges()[4].name, "floor_b");          // 2-3
  EXPECT_EQ(model.faces()[1].name, "floor_b");
}

TEST(CaoReader, HandlesCommentsAndWindowsLineEndings) {
  const std::string text =
      "V1\r\n# comment\r\n3 # points\r\n0 0 0\r\n1 0 0 # x\r\n0 1 0\r\n0\r\n0\r\n1\r\n3 0 1 2\r\n";
  const CaoModel cao = ParseCao(text, "mem.cao", nullptr);
  EXPECT_EQ(cao.points.size(), 3u);
  EXPECT_EQ(cao.faces.size(), 1u);
}

TEST(CaoReader, FacesFromLinesBecomePointLoops) {
  const std::string text = "V1\n3\n0 0 0\n1 0 0\n0 1 0\n3\n0 1\n2 1\n2 0\n1\n3 0 1 2\n0\n";
  const CaoModel cao = ParseCao(text, "mem.cao", nullptr);
  ASSERT_EQ(cao.faces.size(), 1u);
  EXPECT_EQ(cao.faces[0], (std::vector<int>{0, 1, 2}));
}

TEST(CaoReader, ErrorsNameTheLine) {
  const std::string text = "V1\n3\n0 0 0\n1 0 0\n0 1 0\n1\n0 7\n0\n0\n";
  try {
    ParseCao(text, "bad.cao", nullptr);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "bad.cao:7: line 0: index 7 out of range (0..2)");
  }
}

}  // namespace
}  // namespace linetrack
