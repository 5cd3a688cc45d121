// Key views of the hall from exact projections: their store round-trips, their junctions are
// the projected vertices, retrieval ranks a query's own grid view first and transfers true
// line ids; and positioning from two views of a distant facade, where weak perspective holds,
// lands near the truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "matching/views/key_view.h"
#include "matching/views/retrieval.h"
#include "matching/views/view_positioning.h"
#include "matching/views/view_store.h"
#include "models/errors.h"
#include "tests/matching/scene_fixture.h"

namespace linetrack {
namespace {

constexpr double kPixelTol = 1e-6;

class ViewsTest : public ::testing::Test {
 protected:
  // A coarse grid (2 m, 45 degrees) keeps the test fast; `views build` uses 1 m, 30 degrees.
  ViewsTest() : occlusion_(hall_.model()) {
    ViewGrid grid;
    grid.step = 2.0;
    grid.heading_step = DegToRad(45.0);
    db_.camera = hall_.camera();
    db_.model_path = "hall.cao";
    for (const RobotPose& pose : GridPoses(hall_.area(), grid)) {
      KeyView view = KeyViewFromEdges(hall_.model(), Pieces(pose), pose, {});
      view.id = static_cast<int>(db_.views.size());
      db_.views.push_back(std::move(view));
    }
    ComputeViewTokens(&db_);
  }

  std::vector<ProjectedEdge> Pieces(const RobotPose& pose) const {
    return ProjectVisibleEdges(hall_.model(), occlusion_, CamFromWorld(pose), hall_.camera());
  }

  testing::HallFixture hall_;
  OcclusionTester occlusion_;
  ViewDatabase db_;
};

TEST_F(ViewsTest, GridCoversTheNavigableArea) {
  ASSERT_GT(db_.views.size(), 100u);
  EXPECT_EQ(db_.views.size() % 8, 0u);
  for (const KeyView& v : db_.views) {
    EXPECT_TRUE(hall_.area().Contains({v.pose.x, v.pose.y}));
    EXPECT_NEAR(std::remainder(v.pose.x, 2.0), 0.0, 1e-9);
  }
}

TEST_F(ViewsTest, JunctionsAreTheProjectedVertices) {
  int junctions = 0;
  for (const KeyView& v : db_.views) {
    const Eigen::Isometry3d cam_from_world = CamFromWorld(v.pose);
    for (const ViewJunction& j : v.junctions) {
      ++junctions;
      const Eigen::Vector2d vertex =
          hall_.camera().Project(cam_from_world * hall_.model().vertices()[j.point_id]);
      EXPECT_LT((vertex - j.pixel).norm(), kPixelTol);
      ASSERT_GE(j.lines.size(), 2u);
      for (int id : j.lines) {
        const ModelEdge& e = hall_.model().edges()[id];
        EXPECT_TRUE(e.v0 == j.point_id || e.v1 == j.point_id);
      }
    }
  }
  EXPECT_GT(junctions, static_cast<int>(db_.views.size()));
}

TEST_F(ViewsTest, StoreRoundTrips) {
  std::string lines;
  for (const KeyView& v : db_.views)
    lines += KeyViewJsonLine(v);
  const ViewDatabase loaded = ParseViewDatabase(ViewIndexJson(db_), lines, "dir");
  ASSERT_EQ(loaded.views.size(), db_.views.size());
  EXPECT_EQ(loaded.camera.px, db_.camera.px);
  for (size_t v = 0; v < db_.views.size(); v += 17) {
    EXPECT_NEAR(loaded.views[v].pose.heading, db_.views[v].pose.heading, 1e-12);
    ASSERT_EQ(loaded.views[v].segments.size(), db_.views[v].segments.size());
    ASSERT_EQ(loaded.views[v].junctions.size(), db_.views[v].junctions.size());
    EXPECT_EQ(loaded.tokens[v].size(), db_.tokens[v].size());
  }
}

TEST_F(ViewsTest, MalformedStoreNamesTheFileAndLine) {
  const std::string good = KeyViewJsonLine(db_.views.front());
  try {
    ParseViewDatabase(ViewIndexJson(db_), good + "{\"id\": 1, \"pose\": {}}\n", "dir");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("dir/views.jsonl:2:"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ParseViewDatabase("{}", good, "dir"), InputError);
  EXPECT_THROW(ParseViewDatabase(ViewIndexJson(db_), "", "dir"), InputError);
  EXPECT_THROW(LoadViewDatabase("/nonexistent/views"), InputError);
}

TEST_F(ViewsTest, RetrievalRanksTheQuerysOwnViewFirstAndTransfersTrueIds) {
  std::mt19937_64 rng(9);
  std::uniform_int_distribution<size_t> pick(0, db_.views.size() - 1);
  int first = 0, queries = 0, pairs = 0, true_pairs = 0;
  for (int q = 0; q < 20; ++q) {
    const KeyView& truth = db_.views[pick(rng)];
    if (truth.segments.size() < 6) continue;
    ++queries;
    std::vector<Segment2> lines;
    std::vector<int> ids;
    for (const ViewSegment& s : truth.segments) {
      lines.push_back(testing::NoisySegment(s.image, 1.0, 0.3, 0.05, rng));
      ids.push_back(s.line_id);
    }
    const std::vector<RetrievedView> ranked = RetrieveViews(lines, db_, {});
    ASSERT_FALSE(ranked.empty());
    first += ranked.front().view == truth.id;
    for (const TransferredPair& p : ranked.front().pairs) {
      ++pairs;
      true_pairs += ids[p.line] == p.line_id;
    }
  }
  EXPECT_GE(first, queries * 9 / 10);
  EXPECT_GE(true_pairs, pairs * 9 / 10);
}

// A facade 40 m north of the origin, 24 m wide and 10 m tall, in relief (pilasters 1.5 m
// deep, cornices 0.8 m, window frames 0.3 m), as 3D lines: a scene weak perspective suits.
WireframeModel Facade() {
  CaoModel cao;
  cao.files = {"facade.cao"};
  auto box = [&](double x0, double x1, double z0, double z1, double depth) {
    const int base = static_cast<int>(cao.points.size());
    for (double z : {z0, z1}) {
      for (double y : {40.0, 40.0 - depth}) {
        for (double x : {x0, x1})
          cao.points.emplace_back(x, y, z);
      }
    }
    const int edges[][2] = {{2, 3}, {0, 2}, {1, 3}, {6, 7}, {4, 6}, {5, 7}, {2, 6}, {3, 7}};
    for (const auto& e : edges)
      cao.lines.push_back({base + e[0], base + e[1]});
  };
  for (double x : {-9.0, -3.0, 3.0, 9.0})
    box(x - 0.5, x + 0.5, 0.0, 10.0, 1.5);
  box(-12.0, 12.0, 3.3, 3.7, 0.8);
  box(-12.0, 12.0, 6.8, 7.2, 0.8);
  for (double x : {-6.0, 0.0, 6.0}) {
    for (double z : {1.0, 4.5, 8.0})
      box(x - 1.0, x + 1.0, z, z + 1.5, 0.3);
  }
  return WireframeModel::FromCao(cao);
}

TEST(ViewPositioning, TwoViewsOfADistantFacadeGiveThePose) {
  constexpr double kPositionTolM = 0.6;  // 2 % of the 30 m to the facade
  constexpr double kHeadingTolDeg = 1.0;
  const WireframeModel facade = Facade();
  const OcclusionTester occlusion(facade);
  const CameraIntrinsics camera = testing::HallFixture().camera();
  auto lines_at = [&](const RobotPose& pose) {
    std::vector<Segment2> out;
    for (const ProjectedEdge& p :
         ProjectVisibleEdges(facade, occlusion, CamFromWorld(pose), camera)) {
      if (p.image.Length() >= 20.0) out.push_back(p.image);
    }
    return out;
  };
  ViewDatabase db;
  db.camera = camera;
  for (double x : {-4.0, -2.0, 0.0, 2.0, 4.0}) {
    for (double y : {5.0, 8.0, 11.0, 14.0}) {
      for (double h : {75.0, 90.0, 105.0}) {
        const RobotPose pose{x, y, DegToRad(h), 1.3, DegToRad(-8.0)};
        KeyView view = KeyViewFromEdges(
            facade, ProjectVisibleEdges(facade, occlusion, CamFromWorld(pose), camera), pose, {});
        view.id = static_cast<int>(db.views.size());
        db.views.push_back(std::move(view));
      }
    }
  }
  ComputeViewTokens(&db);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> ux(-3.5, 3.5), uy(5.5, 13.5), uh(80.0, 100.0);
  int valid = 0;
  for (int n = 0; n < 10; ++n) {
    const RobotPose truth{ux(rng), uy(rng), DegToRad(uh(rng)), 1.3, DegToRad(-8.0)};
    const ViewPositioning r = LocalizeFromViews(lines_at(truth), db, {});
    if (!r.Valid()) continue;
    ++valid;
    EXPECT_LT(std::hypot(r.pose.x - truth.x, r.pose.y - truth.y), kPositionTolM);
    EXPECT_LT(std::abs(RadToDeg(WrapAngle(r.pose.heading - truth.heading))), kHeadingTolDeg);
    EXPECT_GT(r.reference_depth, 25.0);  // the facade's mean depth, 27-35 m
  }
  EXPECT_GE(valid, 4);
}

}  // namespace
}  // namespace linetrack
