// The renderer's parts: exact scan conversion and near clipping, inverse depth of planes, door
// and window frames found from the hall's 3D lines, and clutter placement.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "models/render/clutter.h"
#include "models/render/frame_decals.h"
#include "models/render/render_scene.h"
#include "models/render/scene_renderer.h"
#include "models/render/sequence.h"
#include "models/render/zbuffer.h"

namespace linetrack {
namespace {

const std::string kHall = std::string(LINETRACK_SOURCE_DIR) + "/models/hall.cao";
const std::string kHallArea = std::string(LINETRACK_SOURCE_DIR) + "/tests/data/hall.nav.json";

constexpr double kTol = 1e-9;
constexpr int kClutterAsked = 12;
constexpr int kClutterMinPlaced = 8;
constexpr double kMaxClutterViewShare = 0.5;  // clutter never fills half of a loop view

NavigableArea HallArea(const WireframeModel& model) {
  NavigableAreaOptions options;
  options.sidecar_path = kHallArea;
  return NavigableArea::FromModel(model, options);
}

int Covered(const ZBuffer& z, uint16_t id) {
  int n = 0;
  for (int j = 0; j < z.height(); ++j)
    for (int i = 0; i < z.width(); ++i)
      n += z.id(i, j) == id ? 1 : 0;
  return n;
}

TEST(ZBuffer, CoversSampleCentresHalfOpen) {
  ZBuffer z;
  z.Resize(8, 8);
  const Eigen::Vector3d far(0.0, 0.0, 0.1), near(0.0, 0.0, 0.5);  // constant inverse depths
  z.ClearToPlanes(far, 0, far, 1);
  // [0.5, 3.5) x [0.5, 3.5) holds the sample centres 1, 2, 3 in each direction.
  z.FillPolygon({{0.5, 0.5}, {3.5, 0.5}, {3.5, 3.5}, {0.5, 3.5}}, near, 7, ZBuffer::Mode::kNearest);
  EXPECT_EQ(Covered(z, 7), 9);
  EXPECT_EQ(z.id(1, 1), 7);
  EXPECT_EQ(z.id(3, 3), 7);
  EXPECT_NE(z.id(4, 3), 7);
  // Two triangles sharing a diagonal through sample centres cover each sample exactly once.
  z.ClearToPlanes(far, 0, far, 1);
  z.FillPolygon({{0, 0}, {6, 0}, {6, 6}}, near, 2, ZBuffer::Mode::kNearest);
  const int first = Covered(z, 2);
  z.FillPolygon({{0, 0}, {6, 6}, {0, 6}}, near * 2.0, 3, ZBuffer::Mode::kNearest);
  EXPECT_EQ(Covered(z, 2) + Covered(z, 3), 36);
  // The nearer second triangle took none of the first's samples: the diagonal is not shared.
  EXPECT_EQ(Covered(z, 2), first);
  EXPECT_EQ(first, 6 + 5 + 4 + 3 + 2 + 1);
}

TEST(ZBuffer, NearestWinsAndDecalsNeedTheSameDepth) {
  ZBuffer z;
  z.Resize(4, 4);
  const Eigen::Vector3d wall(0.0, 0.0, 0.25), nearer(0.0, 0.0, 0.5);
  z.ClearToPlanes(wall, 1, wall, 1);
  const std::vector<Eigen::Vector2d> left = {{-1, -1}, {2, -1}, {2, 5}, {-1, 5}};
  const std::vector<Eigen::Vector2d> all = {{-1, -1}, {5, -1}, {5, 5}, {-1, 5}};
  z.FillPolygon(left, nearer, 2, ZBuffer::Mode::kNearest);    // columns 0, 1 in front
  z.FillPolygon(all, wall, 3, ZBuffer::Mode::kDecal, 1e-4f);  // painted on the wall only
  EXPECT_EQ(z.id(0, 0), 2);
  EXPECT_EQ(z.id(3, 0), 3);
  EXPECT_FLOAT_EQ(z.inverse_depth(0, 0), 0.5f);
}

TEST(ZBuffer, PlaneInverseDepthMatchesRayIntersection) {
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.2, 0.9).normalized();
  const double d = 2.5, px = 800, py = 820, u0 = 330, v0 = 250;
  Eigen::Vector3d c;
  ASSERT_TRUE(PlaneInverseDepth(n, d, {px, py, u0, v0}, &c));
  for (const Eigen::Vector2d& uv : {Eigen::Vector2d(10, 20), Eigen::Vector2d(600, 400)}) {
    const Eigen::Vector3d ray((uv.x() - u0) / px, (uv.y() - v0) / py, 1.0);
    const double z = d / n.dot(ray);  // X = z ray on the plane
    EXPECT_NEAR(c.dot(Eigen::Vector3d(uv.x(), uv.y(), 1.0)), 1.0 / z, kTol);
  }
  EXPECT_FALSE(PlaneInverseDepth(n, 0.0, {px, py, u0, v0}, &c));  // through the optical centre
}

TEST(ZBuffer, ClipsPolygonsAtTheNearPlane) {
  const std::vector<Eigen::Vector3d> quad = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 3}, {-1, 0, 3}};
  const std::vector<Eigen::Vector3d> clipped = ClipPolygonNear(quad, 0.5);
  ASSERT_EQ(clipped.size(), 4u);
  for (const Eigen::Vector3d& p : clipped)
    EXPECT_GE(p.z(), 0.5 - kTol);
  EXPECT_TRUE(ClipPolygonNear({{0, 0, -1}, {1, 0, -1}, {0, 1, -2}}, 0.1).empty());
}

TEST(FrameDecals, FindsTheHallsDoorsAndWindows) {
  const WireframeModel model = WireframeModel::Load(kHall);
  int undrawn = -1;
  const std::vector<FrameGroup> groups = FindFrameGroups(model, &undrawn);
  EXPECT_EQ(undrawn, 0);
  ASSERT_EQ(groups.size(), 6u);  // 4 doors (jamb-lintel-jamb) and 2 windows (closed loops)
  int doors = 0;
  for (const FrameGroup& g : groups) {
    EXPECT_EQ(g.opening.size(), 4u);
    doors += g.door ? 1 : 0;
    EXPECT_EQ(g.edge_ids.size(), g.door ? 3u : 4u);
    for (const Eigen::Vector3d& c : g.opening) {
      const ModelFace& host = model.faces()[g.host_face];
      EXPECT_NEAR(host.normal.dot(c), host.offset, 1e-9);
    }
  }
  EXPECT_EQ(doors, 4);
}

TEST(FrameDecals, BandsLieOutsideTheOpeningAndStartOnTheLine) {
  const WireframeModel model = WireframeModel::Load(kHall);
  const std::vector<FrameGroup> groups = FindFrameGroups(model, nullptr);
  const FrameGroup& group = groups.front();
  const ModelFace& host = model.faces()[group.host_face];
  Eigen::Vector3d e1, e2;
  PlaneBasis(host.normal, &e1, &e2);
  const double width = 0.07;
  const std::vector<RenderSurface> decals = FrameDecals(model, group, 0.7, width, 1);
  ASSERT_EQ(decals.size(), group.edge_ids.size() + 1);
  EXPECT_EQ(decals[0].kind, group.door ? SurfaceKind::kDoorLeaf : SurfaceKind::kWindowPane);
  for (size_t k = 1; k < decals.size(); ++k) {
    const RenderSurface& band = decals[k];
    EXPECT_TRUE(band.decal);
    EXPECT_NEAR(band.offset, host.offset, kTol);
    // The band's centre is outside the opening, half a width from its line.
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& c : band.polygon)
      centre += c / band.polygon.size();
    EXPECT_FALSE(InsidePlanarPolygon(group.opening, centre, e1, e2));
    const Segment3& line = model.edges()[group.edge_ids[k - 1]].segment;
    const Eigen::Vector3d d = line.Direction();
    const Eigen::Vector3d off = (centre - line.a) - (centre - line.a).dot(d) * d;
    EXPECT_NEAR(off.norm(), 0.5 * width, 1e-9);
  }
  // Trim contrasts with a bright wall and with the leaf or pane.
  EXPECT_GT(std::abs(decals[1].albedo - 0.7), 0.3);
  EXPECT_GT(std::abs(decals[1].albedo - decals[0].albedo), 0.15);
}

TEST(Clutter, StandsAgainstWallsAwayFromDoorsAndCameras) {
  const WireframeModel model = WireframeModel::Load(kHall);
  const NavigableArea area = HallArea(model);
  int placed = 0;
  const std::vector<RenderSurface> clutter =
      PlaceClutter(model, area, kClutterAsked, 0.15, 7, &placed);
  EXPECT_GE(placed, kClutterMinPlaced);
  EXPECT_LE(placed, kClutterAsked);
  for (const RenderSurface& s : clutter) {
    EXPECT_EQ(s.kind, SurfaceKind::kClutter);
    for (const Eigen::Vector3d& c : s.polygon) {
      // No part of an object is where a camera may be (the area keeps its clearance).
      EXPECT_FALSE(area.Contains(c.head<2>())) << c.transpose();
      EXPECT_GE(c.z(), -kTol);
    }
  }
  // Deterministic from the seed; another seed places other objects.
  const std::vector<RenderSurface> again = PlaceClutter(model, area, kClutterAsked, 0.15, 7);
  ASSERT_EQ(again.size(), clutter.size());
  EXPECT_TRUE(again.front().polygon == clutter.front().polygon);
  const std::vector<RenderSurface> other = PlaceClutter(model, area, kClutterAsked, 0.15, 8);
  EXPECT_FALSE(other.front().polygon == clutter.front().polygon);
}

TEST(Clutter, NeverHidesMostOfALoopView) {
  const WireframeModel model = WireframeModel::Load(kHall);
  const NavigableArea area = HallArea(model);
  CameraIntrinsics camera;  // the paper's camera at a quarter of its resolution
  camera.width = 160;
  camera.height = 120;
  camera.px = camera.py = 250.0;
  camera.u0 = 80.0;
  camera.v0 = 60.0;
  RenderOptions options;
  options.scene.clutter = 20;
  SceneRenderer renderer(model, camera, options, &area);
  DriveOptions drive;
  drive.speed = 2.0;
  drive.fps = 1.0;
  drive.pan_amplitude = 1.5;  // looking at the walls too
  LoopPathOptions loop;
  loop.wall_distance = 0.6;
  int views_with_clutter = 0;
  for (const SequenceFrame& frame : DriveAlongLoop(LoopInsideArea(area, loop), drive)) {
    const SurfaceMap map = renderer.RenderSurfaces(frame.cam_from_world);
    const auto clutter_pixels = std::count_if(map.surface.begin(), map.surface.end(), [&](int id) {
      return id >= 0 && renderer.scene().surfaces[id].kind == SurfaceKind::kClutter;
    });
    EXPECT_LT(clutter_pixels, kMaxClutterViewShare * map.surface.size()) << "t = " << frame.t;
    views_with_clutter += clutter_pixels > 0 ? 1 : 0;
  }
  EXPECT_GT(views_with_clutter, 5);  // the clutter is there to be seen
}

TEST(RenderScene, AlbedosSeparateOuterWallsFromInnerFaces) {
  for (uint64_t seed : {1u, 2u, 3u}) {
    for (int face = 0; face < 20; ++face) {
      EXPECT_GE(FaceAlbedo(face, true, seed), 0.6);
      EXPECT_LE(FaceAlbedo(face, false, seed), 0.52);
      // Consecutive faces differ by the golden-ratio step (>= 0.38 of the range).
      EXPECT_GT(std::abs(FaceAlbedo(face, true, seed) - FaceAlbedo(face + 1, true, seed)), 0.07);
    }
  }
}

}  // namespace
}  // namespace linetrack
