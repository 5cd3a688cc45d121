// Image-level parts of the tracker, from known ground truth: undistortion of a rendered distorted
// view, the sub-pixel edge locator on steps at known positions, the pose refinement on the edges
// of a rendered hall view from a perturbed start and with an edge on an unmodelled parallel line,
// the alignment of a prediction, the RMS image motion of the model between two poses.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/navigable_area.h"
#include "models/occlusion.h"
#include "models/render/scene_renderer.h"
#include "tracking/tracker/edge_refinement.h"
#include "tracking/tracker/edge_tracker.h"
#include "tracking/tracker/image_undistorter.h"
#include "tracking/tracker/tracking_health.h"

namespace linetrack {
namespace {

const std::string kSource = LINETRACK_SOURCE_DIR;

constexpr double kMaxStepErrorPx = 0.1;           // sub-pixel locator on a clean ramp
constexpr double kMaxUndistortedGreyError = 2.0;  // mean grey-level difference, interior
constexpr double kRefinedPositionTolM = 0.01;
constexpr double kRefinedRotationTolDeg = 0.1;
constexpr double kMotionTolPx = 1e-9;  // RmsImageMotionPx against the pinhole formula

// A vertical step from 50 to 150 grey levels centred at column `edge` (a one-pixel linear ramp,
// as an anti-aliased edge looks).
vpImage<unsigned char> StepImage(double edge) {
  vpImage<unsigned char> image(40, 60);
  for (unsigned v = 0; v < image.getHeight(); ++v) {
    for (unsigned u = 0; u < image.getWidth(); ++u) {
      const double s = std::clamp(u - edge + 0.5, 0.0, 1.0);
      image[v][u] = static_cast<unsigned char>(std::lround(50.0 + 100.0 * s));
    }
  }
  return image;
}

TEST(SubpixelEdge, FindsStepsAtKnownPositions) {
  for (double edge : {30.0, 30.25, 30.5, 30.75}) {
    const double offset = SubpixelEdgeOffset(StepImage(edge), Eigen::Vector2d(29.0, 20.0),
                                             Eigen::Vector2d(1.0, 0.0), 3.0, 3.0);
    EXPECT_NEAR(29.0 + offset, edge, kMaxStepErrorPx) << "edge at " << edge;
  }
  const vpImage<unsigned char> flat(40, 60, 100);
  EXPECT_TRUE(std::isnan(
      SubpixelEdgeOffset(flat, Eigen::Vector2d(29.0, 20.0), Eigen::Vector2d(1.0, 0.0), 3.0, 3.0)));
}

struct HallView {
  WireframeModel model = WireframeModel::Load(kSource + "/models/hall.cao");
  CameraIntrinsics camera = ReadCameraXml(kSource + "/tests/data/camera_wide.xml");
  RobotPose pose{4.3, 1.0, 0.0, 1.3, DegToRad(5.0)};  // looking along the hall at pillar 1

  // Noise-free (the sensor noise is drawn per output pixel, which would favour the raw image).
  vpImage<unsigned char> Render(bool distorted) const {
    RenderOptions options;
    options.apply_distortion = distorted;
    options.noise_sigma = 0.0;
    SceneRenderer renderer(model, camera, options);
    return renderer.Render(CamFromWorld(pose));
  }
};

TEST(ImageUndistorter, UndoesTheRenderersDistortion) {
  const HallView hall;
  const vpImage<unsigned char> distorted = hall.Render(true);
  const vpImage<unsigned char> truth = hall.Render(false);
  ImageUndistorter undistorter(hall.camera);
  ASSERT_FALSE(undistorter.passthrough());
  const vpImage<unsigned char>& undistorted = undistorter.Apply(distorted);
  double fixed = 0.0, raw = 0.0;
  int n = 0;
  for (unsigned v = 40; v < truth.getHeight() - 40; ++v) {
    for (unsigned u = 40; u < truth.getWidth() - 40; ++u) {
      fixed += std::abs(undistorted[v][u] - truth[v][u]);
      raw += std::abs(distorted[v][u] - truth[v][u]);
      ++n;
    }
  }
  EXPECT_LT(fixed / n, kMaxUndistortedGreyError);
  EXPECT_GT(raw / n, 2.0 * fixed / n);  // control: the distortion is visible without the map
  const vpImage<unsigned char> small(10, 10);
  EXPECT_THROW(undistorter.Apply(small), InputError);
  ImageUndistorter plain(hall.camera.Undistorted());
  EXPECT_EQ(&plain.Apply(truth), &truth);
}

// Integer pixels on the visible model edges, as ViSP's moving edges sit on them.
std::vector<Eigen::Vector2d> IntegerSites(const HallView& hall, const Eigen::Isometry3d& pose) {
  const OcclusionTester occlusion(hall.model);
  std::vector<Eigen::Vector2d> sites;
  for (const ProjectedEdge& e :
       ProjectVisibleEdges(hall.model, occlusion, pose, hall.camera.Undistorted())) {
    const double length = e.image.Length();
    for (double s = 6.0; s < length - 6.0; s += 8.0) {
      const Eigen::Vector2d p = e.image.a + s / length * (e.image.b - e.image.a);
      sites.emplace_back(std::round(p.x()), std::round(p.y()));
    }
  }
  return sites;
}

TEST(EdgeRefinement, BringsAPerturbedPoseBackOnTheEdges) {
  const HallView hall;
  const vpImage<unsigned char> image = hall.Render(false);
  const Eigen::Isometry3d truth = CamFromWorld(hall.pose);
  std::vector<Segment3> edges;
  for (const ModelEdge& e : hall.model.edges())
    edges.push_back(e.segment);
  // 6 unknowns: a start 2 cm and 0.1 degree off (about a pixel, as ViSP's integer moving edges
  // leave it), sites from the truth's edges on integer pixels.
  Eigen::Isometry3d start = truth;
  start.pretranslate(Eigen::Vector3d(0.012, -0.01, 0.012));
  start.prerotate(Eigen::AngleAxisd(DegToRad(0.1), Eigen::Vector3d(0.3, 1.0, 0.2).normalized()));
  const EdgeRefinement free = RefineOnEdges(image, hall.camera.Undistorted(), edges,
                                            IntegerSites(hall, truth), {start, std::nullopt}, {});
  ASSERT_TRUE(free.applied);
  const PoseDifference before = ComparePoses(start, truth);
  const PoseDifference after = ComparePoses(free.cam_from_world, truth);
  EXPECT_LT(after.translation, kRefinedPositionTolM);
  EXPECT_LT(RadToDeg(after.rotation), kRefinedRotationTolDeg);
  EXPECT_LT(after.translation, before.translation);
  EXPECT_LT(free.rms_after_px, free.rms_before_px);
  // 3 unknowns with the robot's height and tilt: the result keeps them exactly, roll zero.
  const EdgeRefinement robot =
      RefineOnEdges(image, hall.camera.Undistorted(), edges, IntegerSites(hall, truth),
                    {start, KnownHeightTilt{hall.pose.height, hall.pose.tilt}}, {});
  ASSERT_TRUE(robot.applied);
  const RobotPose refined = RobotPoseFromCamFromWorld(robot.cam_from_world);
  EXPECT_NEAR(refined.height, hall.pose.height, 1e-9);
  EXPECT_NEAR(refined.tilt, hall.pose.tilt, 1e-9);
  EXPECT_NEAR(RollOf(robot.cam_from_world), 0.0, 1e-9);
  EXPECT_LT(ComparePoses(robot.cam_from_world, truth).translation, kRefinedPositionTolM);
}

// A camera rolled 1.5 degrees about its optical axis (its mount's roll): with the known height,
// tilt and roll the refinement of (x, y, heading) comes back on the truth and keeps the roll;
// believing the camera level it cannot.
TEST(EdgeRefinement, KeepsAKnownRollAndConvergesToTheTruth) {
  HallView hall;
  hall.pose.roll = DegToRad(1.5);
  const vpImage<unsigned char> image = hall.Render(false);
  const Eigen::Isometry3d truth = CamFromWorld(hall.pose);
  std::vector<Segment3> edges;
  for (const ModelEdge& e : hall.model.edges())
    edges.push_back(e.segment);
  RobotPose off = hall.pose;
  off.x += 0.012;
  off.y -= 0.01;
  off.heading += DegToRad(0.1);
  const Eigen::Isometry3d start = CamFromWorld(off);
  const std::vector<Eigen::Vector2d> sites = IntegerSites(hall, truth);
  const CameraIntrinsics camera = hall.camera.Undistorted();
  const EdgeRefinement rolled =
      RefineOnEdges(image, camera, edges, sites,
                    {start, KnownHeightTilt{hall.pose.height, hall.pose.tilt, hall.pose.roll}}, {});
  ASSERT_TRUE(rolled.applied) << rolled.refusal;
  const RobotPose refined = RobotPoseFromCamFromWorld(rolled.cam_from_world);
  EXPECT_NEAR(refined.height, hall.pose.height, 1e-9);
  EXPECT_NEAR(refined.tilt, hall.pose.tilt, 1e-9);
  EXPECT_NEAR(refined.roll, hall.pose.roll, 1e-9);
  const PoseDifference error = ComparePoses(rolled.cam_from_world, truth);
  EXPECT_LT(error.translation, kRefinedPositionTolM);
  EXPECT_LT(RadToDeg(error.rotation), kRefinedRotationTolDeg);
  std::printf("rolled camera: refined %.4f m, %.4f deg from the truth\n", error.translation,
              RadToDeg(error.rotation));
  // Control: the same start believed level is refused (the roll moves the image corners by
  // several pixels) or fits worse.
  const EdgeRefinement level = RefineOnEdges(
      image, camera, edges, sites, {start, KnownHeightTilt{hall.pose.height, hall.pose.tilt}}, {});
  std::printf("believed level: %s, rms %.3f px (rolled: %.3f px)\n",
              level.applied ? "applied" : level.refusal.c_str(), level.rms_after_px,
              rolled.rms_after_px);
  EXPECT_TRUE(!level.applied || level.rms_after_px > 2.0 * rolled.rms_after_px);
}

TEST(EdgeRefinement, AlignsAPredictionSeveralPixelsOff) {
  const HallView hall;
  const vpImage<unsigned char> image = hall.Render(false);
  const Eigen::Isometry3d truth = CamFromWorld(hall.pose);
  // A heading 1.5 degrees off: about 13 pixels at f = 500.
  const RobotPose off{hall.pose.x + 0.05, hall.pose.y, hall.pose.heading + DegToRad(1.5),
                      hall.pose.height, hall.pose.tilt};
  const Eigen::Isometry3d predicted = CamFromWorld(off);
  std::vector<Segment3> visible;
  const OcclusionTester occlusion(hall.model);
  for (const ProjectedEdge& e :
       ProjectVisibleEdges(hall.model, occlusion, predicted, hall.camera.Undistorted())) {
    visible.push_back(e.world);
  }
  EdgeAlignmentOptions options;
  options.search_px = 20.0;
  const EdgeRefinement aligned =
      AlignToEdges(image, hall.camera.Undistorted(), visible,
                   {predicted, KnownHeightTilt{hall.pose.height, hall.pose.tilt}}, options);
  ASSERT_TRUE(aligned.applied);
  EXPECT_LT(ComparePoses(aligned.cam_from_world, truth).translation, kRefinedPositionTolM);
  EXPECT_LT(RadToDeg(ComparePoses(aligned.cam_from_world, truth).rotation), kRefinedRotationTolDeg);
}

// One vertical model edge whose image step is moved 1.6 px sideways (an unmodelled parallel line,
// as the outer border of a door casing) and its sites put there: the refinement from the true
// pose sets that edge aside and stays on the truth; without rejections it is pulled off.
TEST(EdgeRefinement, SetsAsideAnEdgeOnAnUnmodelledParallelLine) {
  constexpr double kShiftPx = 1.6;
  const HallView hall;
  vpImage<unsigned char> image = hall.Render(false);
  const Eigen::Isometry3d truth = CamFromWorld(hall.pose);
  const CameraIntrinsics camera = hall.camera.Undistorted();
  std::vector<Segment3> edges;
  for (const ModelEdge& e : hall.model.edges())
    edges.push_back(e.segment);
  const OcclusionTester occlusion(hall.model);
  const std::vector<ProjectedEdge> visible =
      ProjectVisibleEdges(hall.model, occlusion, truth, camera);
  // The longest nearly vertical edge in view.
  const ProjectedEdge* moved = nullptr;
  for (const ProjectedEdge& e : visible) {
    const Eigen::Vector2d d = (e.image.b - e.image.a).normalized();
    if (std::abs(d.y()) > 0.95 && (!moved || e.image.Length() > moved->image.Length())) moved = &e;
  }
  ASSERT_NE(moved, nullptr);
  ASSERT_GT(moved->image.Length(), 100.0);
  const Eigen::Vector2d a = moved->image.a, d = (moved->image.b - a).normalized();
  const Eigen::Vector2d n(-d.y(), d.x());
  const vpImage<unsigned char> original = image;
  for (unsigned v = 0; v < image.getHeight(); ++v) {
    for (unsigned u = 0; u < image.getWidth(); ++u) {
      const Eigen::Vector2d p(u, v);
      const double s = (p - a).dot(n), along = (p - a).dot(d);
      if (s < 0.0 || s >= kShiftPx || along < 0.0 || along > moved->image.Length()) continue;
      const Eigen::Vector2d from = p - 3.0 * n;  // the far side of the step, carried over
      image[v][u] = original[static_cast<unsigned>(std::lround(from.y()))]
                            [static_cast<unsigned>(std::lround(from.x()))];
    }
  }
  std::vector<Eigen::Vector2d> sites;
  for (const ProjectedEdge& e : visible) {
    const double length = e.image.Length();
    for (double s = 6.0; s < length - 6.0; s += 8.0) {
      const Eigen::Vector2d p = e.image.a + s / length * (e.image.b - e.image.a);
      sites.push_back(&e == moved ? Eigen::Vector2d(p + kShiftPx * n)
                                  : Eigen::Vector2d(std::round(p.x()), std::round(p.y())));
    }
  }
  const KnownHeightTilt known{hall.pose.height, hall.pose.tilt};
  const EdgeRefinement kept = RefineOnEdges(image, camera, edges, sites, {truth, known}, {});
  ASSERT_TRUE(kept.applied);
  EXPECT_GE(kept.rejected_edges, 1);
  EXPECT_LT(ComparePoses(kept.cam_from_world, truth).translation, kRefinedPositionTolM);
  EXPECT_LT(RadToDeg(ComparePoses(kept.cam_from_world, truth).rotation), kRefinedRotationTolDeg);
  EXPECT_GT(kept.position_sigma_m, 0.0);
  EXPECT_LT(kept.position_sigma_m, kRefinedPositionTolM);
  EdgeRefinementOptions no_rejection;
  no_rejection.max_edge_rejections = 0;
  const EdgeRefinement pulled =
      RefineOnEdges(image, camera, edges, sites, {truth, known}, no_rejection);
  ASSERT_TRUE(pulled.applied);
  EXPECT_EQ(pulled.rejected_edges, 0);
  EXPECT_GT(ComparePoses(pulled.cam_from_world, truth).translation,
            ComparePoses(kept.cam_from_world, truth).translation);
  std::printf("moved edge of %.0f px: kept %d edges out, %.2f mm; without rejection %.2f mm\n",
              moved->image.Length(), kept.rejected_edges,
              1000.0 * ComparePoses(kept.cam_from_world, truth).translation,
              1000.0 * ComparePoses(pulled.cam_from_world, truth).translation);
}

// A sideways camera step dx in front of a fronto-parallel edge at depth z moves both ends of its
// image by px * dx / z; an end behind the camera is infinite motion, nothing in view none.
TEST(RmsImageMotion, MatchesThePinholeFormula) {
  CameraIntrinsics camera;
  camera.px = camera.py = 500.0;
  camera.u0 = 320.0;
  camera.v0 = 240.0;
  camera.width = 640;
  camera.height = 480;
  // World = camera frame at `from`: an edge 4 m ahead, 0.4 m long, centred.
  const std::vector<Segment3> edges{
      {Eigen::Vector3d(-0.2, 0.1, 4.0), Eigen::Vector3d(0.2, 0.1, 4.0)}};
  const Eigen::Isometry3d from = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d to = from;
  to.pretranslate(Eigen::Vector3d(0.08, 0.0, 0.0));  // points move +8 cm in the camera frame
  EXPECT_NEAR(RmsImageMotionPx(edges, camera, from, to), 500.0 * 0.08 / 4.0, kMotionTolPx);
  Eigen::Isometry3d behind = from;
  behind.pretranslate(Eigen::Vector3d(0.0, 0.0, -5.0));
  EXPECT_TRUE(std::isinf(RmsImageMotionPx(edges, camera, from, behind)));
  Eigen::Isometry3d away = from;
  away.prerotate(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()));  // looking the other way
  EXPECT_EQ(RmsImageMotionPx(edges, camera, away, from), 0.0);
}

}  // namespace
}  // namespace linetrack
