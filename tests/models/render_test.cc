// The renderer against the projection: rendered intensity steps lie on the projected visible
// model edges, the z-buffer orders surfaces correctly, distortion follows the camera model, and
// the output is a function of the seed.
#include "models/render/scene_renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/occlusion.h"
#include "models/robot_pose.h"
#include "models/statistics.h"

namespace linetrack {
namespace {

const std::string kHall = std::string(LINETRACK_SOURCE_DIR) + "/models/hall.cao";
const std::string kPaperCamera = std::string(LINETRACK_SOURCE_DIR) + "/tests/data/camera_paper.xml";
const std::string kWideCamera = std::string(LINETRACK_SOURCE_DIR) + "/tests/data/camera_wide.xml";

constexpr double kEdgeTolPx = 1.0;       // a step must lie this close to the projected line
constexpr double kSearchPx = 3.0;        // half-length of the profile searched across the line
constexpr double kCrowdedPx = 5.0;       // samples this close to another edge are ambiguous
constexpr double kEndMarginPx = 5.0;     // samples this close to a piece's ends are skipped
constexpr double kSampleStepPx = 4.0;    // spacing of samples along an edge
constexpr double kMinStep = 3.0;         // grey levels per pixel: a sample sees a step
constexpr double kMinOnLineShare = 0.9;  // share of stepped samples within kEdgeTolPx
constexpr double kMinStepShare = 0.75;   // share of samples that see a step at all
constexpr double kMaxMedianPx = 0.25;    // median distance of the steps from the lines
constexpr double kMinOnLineShareNoisy = 0.88;  // the same with blur 0.7 px and noise 2 grey levels
constexpr double kMaxMedianNoisyPx = 0.3;
constexpr double kMaxRawOnLineShare = 0.75;  // distorted steps read as undistorted: most miss
constexpr double kDepthTolM = 1e-3;

// Face indices of hall.cao.
constexpr int kWallSouth = 0;
constexpr int kWallEast = 1;
constexpr int kPillar1West = 10;

// Hall views inside the navigable area at the paper's heights and tilts.
const RobotPose kViews[] = {
    {2.0, 2.0, DegToRad(30.0), 1.3, DegToRad(5.0)},
    {7.0, 2.0, DegToRad(150.0), 1.4, DegToRad(3.0)},
    {12.0, 7.5, DegToRad(-150.0), 1.25, DegToRad(8.0)},
    {3.0, 7.0, DegToRad(-60.0), 1.5, DegToRad(0.0)},
    {11.5, 1.5, DegToRad(120.0), 1.35, DegToRad(10.0)},
};

RenderOptions Clean() {
  RenderOptions options;
  options.noise_sigma = 0.0;
  options.blur_sigma = 0.0;
  return options;
}

double Bilinear(const vpImage<unsigned char>& image, const Eigen::Vector2d& p) {
  const int u = static_cast<int>(std::floor(p.x())), v = static_cast<int>(std::floor(p.y()));
  const double a = p.x() - u, b = p.y() - v;
  auto at = [&](int x, int y) { return static_cast<double>(image[y][x]); };
  return (1 - a) * (1 - b) * at(u, v) + a * (1 - b) * at(u + 1, v) + (1 - a) * b * at(u, v + 1) +
         a * b * at(u + 1, v + 1);
}

// Position (pixels along `normal`, from `p`) of the largest intensity step within
// +-kSearchPx: the peak of the derivative taken over +-1 px (robust to noise), refined by a
// parabola; nullopt when the profile leaves the image or the step is below kMinStep.
std::optional<double> StepOffset(const vpImage<unsigned char>& image, const Eigen::Vector2d& p,
                                 const Eigen::Vector2d& normal) {
  constexpr double kDelta = 0.25;  // profile spacing (pixels)
  constexpr int kHalf = 4;         // derivative over +-kHalf samples = +-1 px
  const int n = static_cast<int>(2 * kSearchPx / kDelta) + 2 * kHalf;
  std::vector<double> profile;
  for (int k = 0; k <= n; ++k) {
    const Eigen::Vector2d q = p + ((k - kHalf) * kDelta - kSearchPx) * normal;
    if (q.x() < 0 || q.y() < 0 || q.x() >= image.getWidth() - 1 || q.y() >= image.getHeight() - 1)
      return std::nullopt;
    profile.push_back(Bilinear(image, q));
  }
  std::vector<double> grad(profile.size(), 0.0);
  int best = kHalf;
  for (int k = kHalf; k + kHalf <= n; ++k) {
    grad[k] = std::abs(profile[k + kHalf] - profile[k - kHalf]) / (2 * kHalf * kDelta);
    if (grad[k] > grad[best]) best = k;
  }
  if (grad[best] < kMinStep) return std::nullopt;
  double offset = (best - kHalf) * kDelta - kSearchPx;
  if (best > kHalf && best + kHalf < n) {
    const double l = grad[best - 1], c = grad[best], r = grad[best + 1];
    const double denom = l - 2 * c + r;
    if (denom < 0.0) offset += kDelta * 0.5 * (l - r) / denom;
  }
  return offset;
}

// The distorted pixel whose undistortion (CameraIntrinsics::Undistort, what the renderer uses)
// is `p`: Newton-like fixed point started from Distort(p).
Eigen::Vector2d DistortedPixel(const CameraIntrinsics& camera, const Eigen::Vector2d& p) {
  Eigen::Vector2d q = camera.Distort(p);
  for (int k = 0; k < 20; ++k)
    q += p - camera.Undistort(q);
  return q;
}

double DistanceToSegment(const Eigen::Vector2d& p, const Segment2& s) {
  const Eigen::Vector2d d = s.b - s.a;
  const double t = std::clamp((p - s.a).dot(d) / std::max(d.squaredNorm(), 1e-12), 0.0, 1.0);
  return (s.a + t * d - p).norm();
}

struct EdgeStats {
  int samples = 0, stepped = 0, on_line = 0;
  std::vector<double> errors;
};

// Samples the visible projected edges (undistorted pixels) away from their ends and from other
// edges, and finds the intensity step across each sample: searched around the sample itself or
// (distorted_search) around its distorted pixel, and then (undistort_found) undistorted.
EdgeStats MeasureEdges(const WireframeModel& model, const CameraIntrinsics& camera,
                       const RobotPose& pose, const vpImage<unsigned char>& image,
                       bool distorted_search, bool undistort_found) {
  const OcclusionTester occlusion(model);
  const Eigen::Isometry3d cam_from_world = CamFromWorld(pose);
  EdgeStats stats;
  const std::vector<ProjectedEdge> edges =
      ProjectVisibleEdges(model, occlusion, cam_from_world, camera.Undistorted());
  auto crowded = [&](const Eigen::Vector2d& p, int id) {
    return std::any_of(edges.begin(), edges.end(), [&](const ProjectedEdge& other) {
      return other.edge_id != id && DistanceToSegment(p, other.image) < kCrowdedPx;
    });
  };
  for (const ProjectedEdge& edge : edges) {
    const Eigen::Vector2d a = edge.image.a, b = edge.image.b;
    const double length = (b - a).norm();
    if (length < 2 * kEndMarginPx + kSampleStepPx) continue;
    const Eigen::Vector2d dir = (b - a) / length;
    const Eigen::Vector2d normal(-dir.y(), dir.x());
    for (double s = kEndMarginPx; s <= length - kEndMarginPx; s += kSampleStepPx) {
      const Eigen::Vector2d p = a + s * dir;
      if (crowded(p, edge.edge_id)) continue;
      ++stats.samples;
      const Eigen::Vector2d start = distorted_search ? DistortedPixel(camera, p) : p;
      const std::optional<double> offset = StepOffset(image, start, normal);
      if (!offset) continue;
      ++stats.stepped;
      Eigen::Vector2d found = start + *offset * normal;
      if (undistort_found) found = camera.Undistort(found);
      const double error = std::abs(normal.dot(found - a));
      stats.errors.push_back(error);
      if (error <= kEdgeTolPx) ++stats.on_line;
    }
  }
  return stats;
}

NavigableArea HallArea(const WireframeModel& model) {
  NavigableAreaOptions options;
  options.sidecar_path = std::string(LINETRACK_SOURCE_DIR) + "/tests/data/hall.nav.json";
  return NavigableArea::FromModel(model, options);
}

int DifferentPixels(const vpImage<unsigned char>& a, const vpImage<unsigned char>& b) {
  int n = 0;
  for (unsigned i = 0; i < a.getSize(); ++i)
    n += a.bitmap[i] != b.bitmap[i] ? 1 : 0;
  return n;
}

void ExpectStepsOnEdges(const std::string& camera_file, const RenderOptions& options,
                        double min_on_line_share, double max_median_px) {
  const WireframeModel model = WireframeModel::Load(kHall);
  const CameraIntrinsics camera = ReadCameraXml(camera_file);
  SceneRenderer renderer(model, camera, options);
  const bool distorted = camera.has_distortion && options.apply_distortion;
  for (const RobotPose& pose : kViews) {
    SCOPED_TRACE("view at " + std::to_string(pose.x) + ", " + std::to_string(pose.y));
    const vpImage<unsigned char> image = renderer.Render(CamFromWorld(pose));
    const EdgeStats stats = MeasureEdges(model, camera, pose, image, distorted, distorted);
    ASSERT_GT(stats.samples, 100);
    EXPECT_GE(stats.stepped, kMinStepShare * stats.samples);
    EXPECT_GE(stats.on_line, min_on_line_share * stats.stepped);
    EXPECT_LT(QuantileNearestRank(stats.errors, 0.5), max_median_px);
    if (distorted) {
      // Control: the distorted steps taken as undistorted pixels miss the projection.
      const EdgeStats raw = MeasureEdges(model, camera, pose, image, true, false);
      EXPECT_LT(raw.on_line, kMaxRawOnLineShare * raw.stepped);
    }
  }
}

TEST(SceneRenderer, StepsLieOnTheProjectedEdges) {
  ExpectStepsOnEdges(kPaperCamera, Clean(), kMinOnLineShare, kMaxMedianPx);
}

TEST(SceneRenderer, StepsLieOnTheProjectedEdgesWithBlurAndNoise) {
  ExpectStepsOnEdges(kPaperCamera, RenderOptions(), kMinOnLineShareNoisy, kMaxMedianNoisyPx);
}

TEST(SceneRenderer, DistortedStepsUndistortOntoTheProjection) {
  ExpectStepsOnEdges(kWideCamera, Clean(), kMinOnLineShare, kMaxMedianPx);
}

TEST(SceneRenderer, NearerSurfacesHideFartherOnes) {
  const WireframeModel model = WireframeModel::Load(kHall);
  SceneRenderer renderer(model, ReadCameraXml(kPaperCamera), Clean());
  // From (2, 4.5) looking along +x at 1.3 m: pillar 1's west face (x = 4.75) hides the east wall.
  const SurfaceMap map = renderer.RenderSurfaces(CamFromWorld({2.0, 4.5, 0.0, 1.3, 0.0}));
  auto face_at = [&](int u, int v) {
    const int id = map.At(u, v);
    return id < 0 ? -2 : renderer.scene().surfaces[id].model_face;
  };
  auto kind_at = [&](int u, int v) { return renderer.scene().surfaces[map.At(u, v)].kind; };
  EXPECT_EQ(model.faces()[face_at(320, 240)].corners[0].x(), 4.75);  // pillar1_w
  EXPECT_EQ(face_at(320, 240), kPillar1West);
  EXPECT_NEAR(map.DepthAt(320, 240), 2.75, kDepthTolM);
  // Ray x_n = 0.12 to the right (-y) passes the pillar and pillar 2: the east wall at x = 14.
  EXPECT_EQ(face_at(440, 240), kWallEast);
  EXPECT_NEAR(map.DepthAt(440, 240), 12.0, kDepthTolM);
  // Below the horizon the floor (z = 0 at 1.3 / 0.16 m), above it the ceiling (z = 3).
  EXPECT_EQ(kind_at(440, 400), SurfaceKind::kFloor);
  EXPECT_NEAR(map.DepthAt(440, 400), 1.3 / 0.16, kDepthTolM);
  EXPECT_EQ(kind_at(440, 80), SurfaceKind::kCeiling);
  EXPECT_NEAR(map.DepthAt(440, 80), 1.7 / 0.16, kDepthTolM);
}

TEST(SceneRenderer, FacesAreSeenFromBothSides) {
  const WireframeModel model = WireframeModel::Load(kHall);
  SceneRenderer renderer(model, ReadCameraXml(kPaperCamera), Clean());
  // The south wall (y = 0) from inside (y = 3, looking -y) and from outside (y = -3, looking +y).
  for (const RobotPose& pose : {RobotPose{7.0, 3.0, DegToRad(-90.0), 1.3, 0.0},
                                RobotPose{7.0, -3.0, DegToRad(90.0), 1.3, 0.0}}) {
    const SurfaceMap map = renderer.RenderSurfaces(CamFromWorld(pose));
    EXPECT_EQ(renderer.scene().surfaces[map.At(320, 240)].model_face, kWallSouth);
    EXPECT_NEAR(map.DepthAt(320, 240), 3.0, kDepthTolM);
  }
}

TEST(SceneRenderer, TheSeedDeterminesTheImage) {
  const WireframeModel model = WireframeModel::Load(kHall);
  const NavigableArea area = HallArea(model);
  const CameraIntrinsics camera = ReadCameraXml(kPaperCamera);
  RenderOptions options;
  options.scene.clutter = 8;
  const Eigen::Isometry3d view = CamFromWorld(kViews[0]);
  SceneRenderer first(model, camera, options, &area);
  SceneRenderer second(model, camera, options, &area);
  const vpImage<unsigned char> a = first.Render(view, 3);
  EXPECT_EQ(DifferentPixels(a, second.Render(view, 3)), 0);
  EXPECT_EQ(DifferentPixels(a, first.Render(view, 3)), 0);  // buffers reused between calls
  // Another frame index: another noise draw, same scene.
  EXPECT_GT(DifferentPixels(a, first.Render(view, 4)), a.getSize() / 2);
  options.noise_sigma = 0.0;
  SceneRenderer quiet(model, camera, options, &area);
  EXPECT_EQ(DifferentPixels(quiet.Render(view, 3), quiet.Render(view, 4)), 0);
  // Another seed: other albedos, texture and clutter.
  options.scene.seed = 2;
  SceneRenderer other(model, camera, options, &area);
  EXPECT_GT(DifferentPixels(quiet.Render(view), other.Render(view)), a.getSize() / 2);
}

TEST(SceneRenderer, RejectsBadOptionsAndCameras) {
  const WireframeModel model = WireframeModel::Load(kHall);
  const CameraIntrinsics camera = ReadCameraXml(kPaperCamera);
  RenderOptions options;
  options.supersample = 0;
  EXPECT_THROW(SceneRenderer(model, camera, options), InputError);
  options = RenderOptions();
  options.scene.clutter = 3;  // clutter needs the navigable area
  EXPECT_THROW(SceneRenderer(model, camera, options), InputError);
  CameraIntrinsics sizeless = camera;
  sizeless.width = sizeless.height = 0;
  EXPECT_THROW(SceneRenderer(model, sizeless, RenderOptions()), InputError);
}

}  // namespace
}  // namespace linetrack
