// A short seeded drive through the hall with every effect of the benchmark drives (clutter, a
// person crossing, a blackout, a gain step and ramp, motion blur, the head sweeping at 30 deg/s,
// a view close to a wall, 2.5 % odometry drift), checked against its truth: blackout frames are
// blank, the person is drawn where its walk puts it, the observability flags agree with an
// independent ray-cast count, and the odometry drifts by the stated share.
#include "models/render/drive_renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "models/geometry.h"
#include "models/render/frame_decals.h"
#include "models/render/waypoint_path.h"

namespace linetrack {
namespace {

const std::string kSource = LINETRACK_SOURCE_DIR;
constexpr int kFrames = 80;
constexpr double kDrift = 0.025;
constexpr double kCoveredMaxGrey = 10.0;  // mean grey level of a covered frame
constexpr double kPersonContrast = 10.0;  // mean grey difference the person makes around it
constexpr double kMarginM = 0.02;         // as ObservabilityOptions::occluder_margin

// The wide camera at half size (px = 250, 320 x 240, the same barrel distortion).
CameraIntrinsics SmallWideCamera() {
  CameraIntrinsics c;
  c.width = 320;
  c.height = 240;
  c.px = c.py = 250.0;
  c.u0 = 160.0;
  c.v0 = 120.0;
  c.has_distortion = true;
  c.kud = -0.08;
  c.kdu = 0.085;
  return c;
}

struct Drive {
  WireframeModel model = WireframeModel::Load(kSource + "/models/hall.cao");
  NavigableArea area;
  CameraIntrinsics camera = SmallWideCamera();
  std::unique_ptr<SceneRenderer> renderer;
  std::unique_ptr<DriveRenderer> drive;
  DriveEffectsOptions effects;
  std::vector<vpImage<unsigned char>> images;
  std::vector<FrameTruth> truth;

  Drive() {
    NavigableAreaOptions area_options;
    area_options.sidecar_path = kSource + "/tests/data/hall.nav.json";
    area = NavigableArea::FromModel(model, area_options);
    RenderOptions options;
    options.scene.seed = 5;
    options.scene.clutter = 6;
    renderer = std::make_unique<SceneRenderer>(model, camera, options, &area);
    DriveOptions d;
    d.speed = 0.8;
    d.frames = kFrames;
    d.pan_amplitude = DegToRad(35.0);
    d.pan_rate = DegToRad(30.0);
    const SampledPath path = PathThroughWaypoints(
        ParseWaypoints("2,1.2\n5,1.0\n6.5,0.6,-90\n8.5,1.2\n", "test"), {}, "test");
    const std::vector<SequenceFrame> frames = DriveAlongPath(path, d);
    effects.seed = 5;
    effects.people = 1;
    effects.blackouts = 1;
    effects.exposure_changes = 2;
    effects.shutter = 0.02;
    effects.max_shutter_samples = 3;  // blur enough, and a fast test
    drive = std::make_unique<DriveRenderer>(model, renderer.get(), frames,
                                            PlanDriveEffects(frames, effects, &area), effects);
    for (int k = 0; k < kFrames; ++k) {
      DriveRenderer::Rendered r = drive->RenderFrame(k);
      images.push_back(std::move(r.image));
      truth.push_back(r.truth);
    }
  }
};

const Drive& TestDrive() {
  static const Drive* drive = new Drive();
  return *drive;
}

double MeanGrey(const vpImage<unsigned char>& image, int u0, int v0, int u1, int v1) {
  double sum = 0.0;
  int n = 0;
  for (int v = std::max(0, v0); v < std::min<int>(image.getHeight(), v1); ++v) {
    for (int u = std::max(0, u0); u < std::min<int>(image.getWidth(), u1); ++u, ++n)
      sum += image[v][u];
  }
  return n > 0 ? sum / n : 0.0;
}

// Distance from `eye` along the ray to `target` at which the segment meets a solid unmodelled
// surface (clutter, people), or infinity.
double NearestUnmodelledHit(const std::vector<RenderSurface>& surfaces, const Eigen::Vector3d& eye,
                            const Eigen::Vector3d& target) {
  const Eigen::Vector3d dir = (target - eye).normalized();
  double nearest = std::numeric_limits<double>::infinity();
  for (const RenderSurface& s : surfaces) {
    if (s.decal || (s.kind != SurfaceKind::kClutter && s.kind != SurfaceKind::kPerson)) continue;
    const double along = s.normal.dot(dir);
    if (std::abs(along) < 1e-12) continue;
    const double d = (s.offset - s.normal.dot(eye)) / along;
    if (!(d > 0.0) || d >= nearest) continue;
    const Eigen::Vector3d hit = eye + d * dir;
    Eigen::Vector3d e1, e2;
    PlaneBasis(s.normal, &e1, &e2);
    if (InsidePlanarPolygon(s.polygon, hit, e1, e2)) nearest = d;
  }
  return nearest;
}

// Model edges with an unhidden piece of at least 40 px: ProjectVisibleEdges' pieces sampled every
// 0.25 px of their image, each sample cast against the unmodelled polygons.
int IndependentEdgeCount(const Drive& d, size_t k) {
  const SequenceFrame& frame = d.drive->frames()[k];
  std::vector<RenderSurface> surfaces = d.renderer->scene().surfaces;
  const std::vector<RenderSurface> people = d.drive->effects().PeopleAt(frame.t);
  surfaces.insert(surfaces.end(), people.begin(), people.end());
  const Eigen::Vector3d eye = frame.cam_from_world.inverse().translation();
  const CameraIntrinsics camera = d.camera.Undistorted();
  std::map<int, double> longest;
  for (const ProjectedEdge& piece :
       ProjectVisibleEdges(d.model, OcclusionTester(d.model), frame.cam_from_world, camera)) {
    const int n = std::max(2, static_cast<int>(4.0 * (piece.image.b - piece.image.a).norm()));
    double run = 0.0;
    Eigen::Vector2d previous;
    for (int i = 0; i <= n; ++i) {
      const Eigen::Vector3d x = piece.world.a + (piece.world.b - piece.world.a) * (double(i) / n);
      const Eigen::Vector3d in_cam = frame.cam_from_world * x;
      const Eigen::Vector2d uv = camera.Project(in_cam);
      const double depth = (x - eye).norm();
      const bool hidden =
          NearestUnmodelledHit(surfaces, eye, x) < depth * 0.99 - kMarginM * depth / in_cam.z();
      run = hidden ? 0.0 : run + (i == 0 ? 0.0 : (uv - previous).norm());
      longest[piece.edge_id] = std::max(longest[piece.edge_id], run);
      previous = uv;
    }
  }
  return static_cast<int>(std::count_if(longest.begin(), longest.end(),
                                        [](const auto& e) { return e.second >= 40.0; }));
}

TEST(DriveRenderer, EveryEffectIsInTheDrive) {
  const Drive& d = TestDrive();
  const DriveEffects& e = d.drive->effects();
  EXPECT_EQ(e.people.size(), 1u);
  ASSERT_EQ(e.blackouts.size(), 1u);
  ASSERT_EQ(e.gain.size(), 5u);  // start, a step (two knots at one time), a ramp
  EXPECT_EQ(e.gain[1].t, e.gain[2].t);
  EXPECT_GT(e.gain[4].t - e.gain[3].t, 1.0);
  EXPECT_GT(d.renderer->scene().clutter_placed, 0);
  auto any = [&](auto predicate) { return std::any_of(d.truth.begin(), d.truth.end(), predicate); };
  EXPECT_TRUE(any([](const FrameTruth& t) { return t.shutter_samples > 1 && t.blur_px > 2.0; }));
  EXPECT_TRUE(
      any([](const FrameTruth& t) { return t.centre_depth_m > 0 && t.centre_depth_m < 1; }));
  EXPECT_TRUE(any([](const FrameTruth& t) { return t.people_share > 0.05; }));
  EXPECT_TRUE(any([](const FrameTruth& t) { return std::abs(t.pan_deg) > 30.0; }));
  EXPECT_TRUE(any([](const FrameTruth& t) { return t.gain < 0.9 || t.gain > 1.1; }));
  EXPECT_TRUE(any([](const FrameTruth& t) { return t.observable; }));
  EXPECT_TRUE(any([](const FrameTruth& t) { return !t.observable && !t.covered; }));
}

TEST(DriveRenderer, BlackoutFramesAreBlankAndUnobservable) {
  const Drive& d = TestDrive();
  const auto [start, end] = d.drive->effects().blackouts.front();
  int covered = 0;
  for (size_t k = 0; k < d.truth.size(); ++k) {
    const bool inside = d.truth[k].t >= start && d.truth[k].t < end;
    EXPECT_EQ(d.truth[k].covered, inside) << k;
    if (!inside) continue;
    ++covered;
    EXPECT_LT(MeanGrey(d.images[k], 0, 0, 320, 240), kCoveredMaxGrey) << k;
    EXPECT_FALSE(d.truth[k].observable);
  }
  EXPECT_NEAR(covered, 6, 1);  // 0.6 s at 10 frames/s
}

TEST(DriveRenderer, ThePersonIsDrawnWhereItsWalkPutsIt) {
  const Drive& d = TestDrive();
  const PersonWalk& walk = d.drive->effects().people.front();
  const OcclusionTester occlusion(d.model);
  RenderOptions options;
  options.scene.seed = 5;
  options.scene.clutter = 6;
  SceneRenderer plain(d.model, d.camera, options, &d.area);  // the same scene without people
  int seen = 0;
  for (size_t k = 0; k < d.truth.size(); ++k) {
    const SequenceFrame& frame = d.drive->frames()[k];
    if (!walk.InSceneAt(frame.t)) {
      EXPECT_EQ(d.truth[k].people_share, 0.0) << k;
      continue;
    }
    const Eigen::Vector2d p = walk.PositionAt(frame.t);
    const Eigen::Vector3d chest(p.x(), p.y(), 0.7 * walk.height);
    const Eigen::Vector3d in_cam = frame.cam_from_world * chest;
    const Eigen::Vector3d eye = frame.cam_from_world.inverse().translation();
    if (d.truth[k].covered || in_cam.z() < 0.3 || occlusion.Blocked(eye, chest)) continue;
    const Eigen::Vector2d uv = d.camera.Distort(d.camera.Project(in_cam));
    if (uv.x() < 12 || uv.y() < 12 || uv.x() > 308 || uv.y() > 228) continue;
    ++seen;
    EXPECT_GT(d.truth[k].people_share, 0.0) << k;
    const vpImage<unsigned char> without = plain.Render(frame.cam_from_world, static_cast<int>(k));
    const int u = static_cast<int>(uv.x()), v = static_cast<int>(uv.y());
    double difference = 0.0;  // the person's box against the wall behind it, over a window
    for (int dv = -4; dv <= 4; ++dv)
      for (int du = -4; du <= 4; ++du)
        difference += std::abs(d.images[k][v + dv][u + du] - without[v + dv][u + du]) / 81.0;
    EXPECT_GT(difference, kPersonContrast) << "frame " << k << " at " << uv.transpose();
  }
  EXPECT_GE(seen, 5);
}

TEST(DriveRenderer, ObservabilityAgreesWithAnIndependentRayCast) {
  const Drive& d = TestDrive();
  int flags_checked = 0;
  for (size_t k = 0; k < d.truth.size(); k += 7) {
    if (d.truth[k].covered) continue;
    const int independent = IndependentEdgeCount(d, k);
    EXPECT_NEAR(d.truth[k].observable_edges, independent, 1) << "frame " << k;
    if (std::abs(independent - 3) <= 1) continue;  // within one edge of the threshold
    ++flags_checked;
    EXPECT_EQ(d.truth[k].observable, independent >= 3) << "frame " << k;
  }
  EXPECT_GE(flags_checked, 5);
}

TEST(DriveRenderer, OdometryDriftsByTheStatedShare) {
  const Drive& d = TestDrive();
  const std::vector<PriorRecord> priors =
      SimulateOdometryPriors(d.drive->frames(), OdometryForDrift(kDrift, 5));
  const OdometryDrift drift = MeasureOdometryDrift(d.drive->frames(), priors, 5.0);
  EXPECT_GT(drift.windows, 0);
  EXPECT_LE(drift.max_share, 1.2 * kDrift);
  EXPECT_GE(drift.whole_share, 0.5 * kDrift);
}

}  // namespace
}  // namespace linetrack
