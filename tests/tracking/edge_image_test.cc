// Image-level parts of the tracker, from known ground truth: undistortion of a rendered distorted
// view, the sub-pixel edge locator on steps at known positions, the pose refinement on the edges
// of a rendered hall view from a perturbed start, the alignment of a prediction.
#include <gtest/gtest.h>

#include <cmath>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/navigable_area.h"
#include "models/occlusion.h"
#include "models/render/scene_renderer.h"
#include "tracking/tracker/edge_refinement.h"
#include "tracking/tracker/image_undistorter.h"
#include "tracking/tracker/tracking_health.h"

namespace linetrack {
namespace {

const std::string kSource = LINETRACK_SOURCE_DIR;

constexpr double kMaxStepErrorPx = 0.1;           // sub-pixel locator on a clean ramp
constexpr double kMaxUndistortedGreyError = 2.0;  // mean grey-level difference, interior
constexpr double kRefinedPositionTolM = 0.01;
constexpr double kRefinedRotationTolDeg = 0.1;

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
  const EdgeRefinement free =
      RefineOnEdges(image, hall.camera.Undistorted(), edges, IntegerSites(hall, truth), start, {});
  ASSERT_TRUE(free.applied);
  const PoseDifference before = ComparePoses(start, truth);
  const PoseDifference after = ComparePoses(free.cam_from_world, truth);
  EXPECT_LT(after.translation, kRefinedPositionTolM);
  EXPECT_LT(RadToDeg(after.rotation), kRefinedRotationTolDeg);
  EXPECT_LT(after.translation, before.translation);
  EXPECT_LT(free.rms_after_px, free.rms_before_px);
  // 3 unknowns with the robot's height and tilt: the result keeps them exactly, roll zero.
  const EdgeRefinement robot =
      RefineOnEdges(image, hall.camera.Undistorted(), edges, IntegerSites(hall, truth), start, {},
                    KnownHeightTilt{hall.pose.height, hall.pose.tilt});
  ASSERT_TRUE(robot.applied);
  const RobotPose refined = RobotPoseFromCamFromWorld(robot.cam_from_world);
  EXPECT_NEAR(refined.height, hall.pose.height, 1e-9);
  EXPECT_NEAR(refined.tilt, hall.pose.tilt, 1e-9);
  EXPECT_NEAR(RollOf(robot.cam_from_world), 0.0, 1e-9);
  EXPECT_LT(ComparePoses(robot.cam_from_world, truth).translation, kRefinedPositionTolM);
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
      AlignToEdges(image, hall.camera.Undistorted(), visible, predicted, options,
                   KnownHeightTilt{hall.pose.height, hall.pose.tilt});
  ASSERT_TRUE(aligned.applied);
  EXPECT_LT(ComparePoses(aligned.cam_from_world, truth).translation, kRefinedPositionTolM);
  EXPECT_LT(RadToDeg(ComparePoses(aligned.cam_from_world, truth).rotation), kRefinedRotationTolDeg);
}

}  // namespace
}  // namespace linetrack
