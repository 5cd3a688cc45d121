// The line extractors on rendered hall views with known edges: every observable model edge of
// 40 px or more is found, endpoints within tolerance, for each detector; with a distorting
// camera the undistorted segments land on the undistorted projection.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "matching/evaluation/line_evaluation.h"
#include "matching/lines/line_extractor.h"
#include "models/errors.h"
#include "models/render/scene_renderer.h"
#include "models/robot_pose.h"
#include "models/statistics.h"

namespace linetrack {
namespace {

const std::string kHall = std::string(LINETRACK_SOURCE_DIR) + "/models/hall.cao";
const std::string kPaperCamera = std::string(LINETRACK_SOURCE_DIR) + "/tests/data/camera_paper.xml";
const std::string kWideCamera = std::string(LINETRACK_SOURCE_DIR) + "/tests/data/camera_wide.xml";

constexpr double kMinEdgeLengthPx = 40.0;     // the "edges longer than 40 px"
constexpr double kMinContrast = 8.0;          // grey levels across an observable edge sample
constexpr double kMaxMedianEndpointPx = 2.0;  // the endpoint target
// Share of the observable edges found, per detector: a little below what `linetrack bench
// lines` measures on 40 rendered views (docs/lines.md): FLD (the default) and EDLines find
// nearly all, LSD misses some faint ones, the paper's Hough detector more.
double MinFoundShare(LineDetectorKind detector) {
  switch (detector) {
    case LineDetectorKind::kFld:
      return 0.97;
    case LineDetectorKind::kEdlines:
      return 0.95;
    case LineDetectorKind::kLsd:
      return 0.9;
    case LineDetectorKind::kHough:
      return 0.85;
  }
  return 1.0;
}

// Hall views inside the navigable area (heights 1.2-1.5 m, tilts 0-10 deg), facing walls,
// pillars, the partition, doors and windows.
const RobotPose kViews[] = {
    {1.5, 1.5, DegToRad(45.0), 1.3, DegToRad(4.0)},
    {8.0, 1.2, DegToRad(100.0), 1.45, DegToRad(6.0)},
    {12.5, 4.0, DegToRad(170.0), 1.2, DegToRad(2.0)},
    {4.0, 8.0, DegToRad(-20.0), 1.35, DegToRad(9.0)},
    {11.0, 8.0, DegToRad(-100.0), 1.5, DegToRad(0.0)},
    {6.5, 5.5, DegToRad(-160.0), 1.25, DegToRad(7.0)},
};

struct Tally {
  int edges = 0, found = 0;
  std::vector<double> endpoint_errors;
};

Tally DetectOnViews(const std::string& camera_file, LineDetectorKind detector) {
  const WireframeModel model = WireframeModel::Load(kHall);
  const OcclusionTester occlusion(model);
  const CameraIntrinsics camera = ReadCameraXml(camera_file);
  RenderOptions noisy;  // blur 0.7 px, noise 2 grey levels
  RenderOptions clean = noisy;
  clean.noise_sigma = 0.0;
  SceneRenderer renderer(model, camera, noisy);
  SceneRenderer clean_renderer(model, camera, clean);
  LineExtractionOptions options;
  options.detector = detector;
  LineExtractor extractor(options, camera);
  Tally tally;
  for (const RobotPose& pose : kViews) {
    const Eigen::Isometry3d cam_from_world = CamFromWorld(pose);
    const std::vector<ProjectedEdge> truth =
        ProjectVisibleEdges(model, occlusion, cam_from_world, camera.Undistorted());
    const std::vector<ObservablePiece> observable = ObservablePieces(
        truth, clean_renderer.Render(cam_from_world), clean_renderer.RenderSurfaces(cam_from_world),
        clean_renderer.scene(), camera, cam_from_world, kMinContrast);
    const LineExtraction extraction = extractor.Extract(renderer.Render(cam_from_world));
    const DetectionEvaluation evaluation =
        EvaluateDetections(observable, extraction.segments, kMinEdgeLengthPx, {});
    tally.edges += static_cast<int>(evaluation.edges.size());
    tally.found += evaluation.found;
    tally.endpoint_errors.insert(tally.endpoint_errors.end(), evaluation.endpoint_errors.begin(),
                                 evaluation.endpoint_errors.end());
  }
  return tally;
}

class DetectorOnRenderedHall : public ::testing::TestWithParam<LineDetectorKind> {};

TEST_P(DetectorOnRenderedHall, FindsTheObservableModelEdges) {
  for (const std::string& camera : {kPaperCamera, kWideCamera}) {
    SCOPED_TRACE(camera);
    const Tally tally = DetectOnViews(camera, GetParam());
    ASSERT_GT(tally.edges, 20);
    EXPECT_GE(tally.found, MinFoundShare(GetParam()) * tally.edges)
        << tally.found << " of " << tally.edges;
    EXPECT_LE(QuantileNearestRank(tally.endpoint_errors, 0.5), kMaxMedianEndpointPx);
  }
}

INSTANTIATE_TEST_SUITE_P(AllDetectors, DetectorOnRenderedHall,
                         ::testing::ValuesIn(AllLineDetectors()),
                         [](const ::testing::TestParamInfo<LineDetectorKind>& info) {
                           return LineDetectorName(info.param);
                         });

// A synthetic image: a bright rectangle on a dark background, corners known exactly.
vpImage<unsigned char> Rectangle(int width, int height, int u0, int v0, int u1, int v1) {
  vpImage<unsigned char> image(height, width, 40);
  for (int v = v0; v < v1; ++v) {
    for (int u = u0; u < u1; ++u)
      image[v][u] = 200;
  }
  return image;
}

TEST(LineExtractor, FindsTheFourSidesOfARectangleWithEveryDetector) {
  // Sides of the bright region [100, 500) x [80, 400): steps between pixels 99|100 and 499|500.
  constexpr double kSideTolPx = 1.0;
  const vpImage<unsigned char> image = Rectangle(640, 480, 100, 80, 500, 400);
  const Segment2 sides[] = {{{99.5, 79.5}, {499.5, 79.5}},
                            {{499.5, 79.5}, {499.5, 399.5}},
                            {{99.5, 399.5}, {499.5, 399.5}},
                            {{99.5, 79.5}, {99.5, 399.5}}};
  for (LineDetectorKind kind : AllLineDetectors()) {
    SCOPED_TRACE(LineDetectorName(kind));
    LineExtractionOptions options;
    options.detector = kind;
    LineExtractor extractor(options);
    const std::vector<Segment2> segments = extractor(image);
    ASSERT_EQ(segments.size(), 4u);
    for (const Segment2& side : sides) {
      DetectionMatchOptions tolerance;
      tolerance.max_offset_px = kSideTolPx;
      EXPECT_EQ(std::count_if(segments.begin(), segments.end(),
                              [&](const Segment2& s) {
                                return DetectionOnEdge(side, s, tolerance) &&
                                       EdgeCoverage(side, {s}) > 0.9;
                              }),
                1);
    }
  }
}

TEST(LineExtractor, RegionOfInterestKeepsItsLinesInImagePixels) {
  const vpImage<unsigned char> image = Rectangle(640, 480, 100, 80, 500, 400);
  LineExtractionOptions options;
  options.roi = {0, 0, 320, 480};  // the left half: the left side and halves of top and bottom
  LineExtractor extractor(options);
  const std::vector<Segment2> segments = extractor(image);
  ASSERT_EQ(segments.size(), 3u);
  for (const Segment2& s : segments) {
    EXPECT_LT(std::max(s.a.x(), s.b.x()), 320.0);
    EXPECT_GT(std::min(s.a.x(), s.b.x()), 98.0);
  }
}

TEST(LineExtractor, TheFunctionFormGivesTheSameSegments) {
  const vpImage<unsigned char> image = Rectangle(640, 480, 100, 80, 500, 400);
  const LineExtractorFunction extract = MakeLineExtractorFunction({});
  LineExtractor extractor({});
  const std::vector<Segment2> a = extract(image), b = extractor(image);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i)
    EXPECT_EQ(a[i].a, b[i].a);
}

TEST(LineExtractor, BadImagesAndOptionsThrowInputError) {
  const CameraIntrinsics camera = ReadCameraXml(kPaperCamera);  // 640x480
  LineExtractor extractor({}, camera);
  EXPECT_THROW(extractor.Extract(vpImage<unsigned char>()), InputError);
  EXPECT_THROW(extractor.Extract(vpImage<unsigned char>(240, 320, 0)), InputError);
  LineExtractionOptions outside;
  outside.roi = {600, 0, 100, 100};
  LineExtractor roi_extractor(outside);
  EXPECT_THROW(roi_extractor.Extract(vpImage<unsigned char>(480, 640, 0)), InputError);
  LineExtractionOptions bad;
  bad.min_length_px = std::nan("");
  EXPECT_THROW(LineExtractor{bad}, InputError);
  bad = {};
  bad.merge_options.max_angle_deg = 95.0;
  EXPECT_THROW(LineExtractor{bad}, InputError);
  // A flat image has no lines (not an error).
  EXPECT_TRUE(extractor(vpImage<unsigned char>(480, 640, 90)).empty());
}

TEST(LineDetectorName, RoundTrips) {
  for (LineDetectorKind kind : AllLineDetectors())
    EXPECT_EQ(ParseLineDetector(LineDetectorName(kind)), kind);
  EXPECT_FALSE(ParseLineDetector("canny").has_value());
}

}  // namespace
}  // namespace linetrack
