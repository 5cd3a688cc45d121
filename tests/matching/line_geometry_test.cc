// Pure pieces of line extraction: segment fitting, collinear merging, chain splitting, the
// detection-vs-truth judging, and the undistortion of segments (exact synthetic data).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "matching/evaluation/line_evaluation.h"
#include "matching/lines/hough_lines.h"
#include "matching/lines/segment_fitting.h"
#include "matching/lines/undistortion.h"

#include <opencv2/imgproc.hpp>

namespace linetrack {
namespace {

constexpr double kExactTol = 1e-9;
constexpr double kRoundTripTolPx = 1e-9;  // DistortedPixelOf inverts Undistort exactly
constexpr double kStraightTolPx = 1e-6;   // undistorted samples of a straight line: on it
constexpr double kRemapTolPx = 1.0 / 32;  // cv::remap's fixed-point maps: 1/32 px steps

CameraIntrinsics WideCamera() {
  CameraIntrinsics camera;
  camera.width = 640;
  camera.height = 480;
  camera.px = camera.py = 500.0;
  camera.u0 = 320.0;
  camera.v0 = 240.0;
  camera.has_distortion = true;
  camera.kud = -0.08;
  camera.kdu = 0.085;
  return camera;
}

double DistanceToLine(const Eigen::Vector2d& p, const Segment2& s) {
  const Eigen::Vector2d d = (s.b - s.a).normalized();
  return std::abs(Cross2(d, p - s.a));
}

TEST(FitSegment, RecoversTheLineAndExtentOfExactPoints) {
  const Segment2 truth{{10.0, 20.0}, {210.0, 70.0}};
  std::vector<Eigen::Vector2d> points;
  for (int k = 0; k <= 50; ++k)
    points.push_back(truth.a + (truth.b - truth.a) * (k / 50.0));
  const Segment2 fit = FitSegment(points);
  // Either direction: the ends are the extreme points.
  const bool forward = (fit.a - truth.a).norm() < (fit.a - truth.b).norm();
  EXPECT_NEAR(((forward ? fit.a : fit.b) - truth.a).norm(), 0.0, kExactTol);
  EXPECT_NEAR(((forward ? fit.b : fit.a) - truth.b).norm(), 0.0, kExactTol);
  EXPECT_NEAR(LineFitRms(points, fit), 0.0, kExactTol);
}

TEST(FitSegment, NoisyPointsAverageOut) {
  constexpr double kNoisePx = 0.5, kTolPx = 0.15;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, kNoisePx);
  const Segment2 truth{{0.0, 0.0}, {300.0, 100.0}};
  const Eigen::Vector2d normal = Eigen::Vector2d(-100.0, 300.0).normalized();
  std::vector<Eigen::Vector2d> points;
  for (int k = 0; k <= 300; ++k)
    points.push_back(truth.a + (truth.b - truth.a) * (k / 300.0) + noise(rng) * normal);
  const Segment2 fit = FitSegment(points);
  EXPECT_LT(DistanceToLine(fit.a, truth), kTolPx);
  EXPECT_LT(DistanceToLine(fit.b, truth), kTolPx);
  EXPECT_NEAR(LineFitRms(points, fit), kNoisePx, 0.1);
}

TEST(MergeCollinearSegments, JoinsFragmentsOfOneLine) {
  const Segment2 line{{0.0, 100.0}, {400.0, 140.0}};
  auto along = [&](double t) { return line.a + (line.b - line.a) * t; };
  // Three fragments with gaps of about 8 px, one slightly offset (0.5 px).
  const Eigen::Vector2d n = Eigen::Vector2d(-40.0, 400.0).normalized();
  std::vector<Segment2> fragments = {{along(0.0), along(0.3)},
                                     {along(0.32) + 0.5 * n, along(0.6) + 0.5 * n},
                                     {along(0.62), along(1.0)}};
  const std::vector<Segment2> merged = MergeCollinearSegments(fragments, {});
  ASSERT_EQ(merged.size(), 1u);
  EXPECT_LT(DistanceToLine(merged[0].a, line), 0.5);
  EXPECT_LT(DistanceToLine(merged[0].b, line), 0.5);
  EXPECT_NEAR(merged[0].Length(), line.Length(), 0.5);
}

TEST(MergeCollinearSegments, KeepsParallelCrossingAndDistantLinesApart) {
  const CollinearMergeOptions options;  // 2 deg, 2 px, 12 px gap
  const Segment2 a{{0.0, 0.0}, {100.0, 0.0}};
  EXPECT_TRUE(AreCollinearFragments(a, {{105.0, 0.5}, {200.0, 0.5}}, options));
  EXPECT_FALSE(AreCollinearFragments(a, {{0.0, 5.0}, {100.0, 5.0}}, options));     // parallel
  EXPECT_FALSE(AreCollinearFragments(a, {{50.0, -50.0}, {50.0, 50.0}}, options));  // crossing
  EXPECT_FALSE(AreCollinearFragments(a, {{130.0, 0.0}, {200.0, 0.0}}, options));   // 30 px gap
  EXPECT_FALSE(AreCollinearFragments(a, {{110.0, 0.0}, {200.0, 10.0}}, options));  // 6.3 deg
  EXPECT_EQ(MergeCollinearSegments({a, {{0.0, 5.0}, {100.0, 5.0}}}, options).size(), 2u);
}

TEST(SplitRuns, BreaksAtGapsAndDropsShortRuns) {
  const std::vector<double> positions = {0, 1, 2, 3, 10, 11, 12, 13, 14, 15, 40, 41};
  const auto runs = SplitRuns(positions, 3.0, 4.0);
  ASSERT_EQ(runs.size(), 1u);  // [0, 3] is 3 px long, [40, 41] 1 px: dropped
  EXPECT_EQ(runs[0], std::make_pair(4, 9));
  EXPECT_EQ(SplitRuns(positions, 10.0, 1.0).size(), 2u);
  EXPECT_TRUE(SplitRuns({}, 3.0, 1.0).empty());
}

TEST(DetectionJudging, CoverageAndOnEdgeTolerances) {
  const Segment2 edge{{0.0, 0.0}, {200.0, 0.0}};
  const DetectionMatchOptions options;  // 2 deg, 2 px, 5 px margin
  EXPECT_TRUE(DetectionOnEdge(edge, {{10.0, 1.0}, {90.0, 1.5}}, options));
  EXPECT_FALSE(DetectionOnEdge(edge, {{10.0, 3.0}, {90.0, 3.0}}, options));    // offset
  EXPECT_FALSE(DetectionOnEdge(edge, {{210.0, 0.0}, {300.0, 0.0}}, options));  // beyond
  EXPECT_NEAR(EdgeCoverage(edge, {{{-10.0, 0.0}, {50.0, 0.0}}, {{40.0, 0.0}, {100.0, 0.0}}}), 0.5,
              kExactTol);
  // One detection covering the whole edge: found, endpoint errors are the overhangs.
  ProjectedEdge truth;
  truth.edge_id = 3;
  truth.image = edge;
  const DetectionEvaluation e = EvaluateDetections(std::vector<ProjectedEdge>{truth},
                                                   {{{-1.0, 0.0}, {202.0, 0.5}}}, 40.0, options);
  ASSERT_EQ(e.edges.size(), 1u);
  EXPECT_TRUE(e.edges[0].found);
  ASSERT_EQ(e.endpoint_errors.size(), 2u);
  EXPECT_NEAR(e.edges[0].endpoint_error[0], 1.0, kExactTol);
  EXPECT_NEAR(e.edges[0].endpoint_error[1], std::hypot(2.0, 0.5), kExactTol);
  EXPECT_EQ(
      TrueCorrespondences({truth}, {{{-1.0, 0.0}, {202.0, 0.5}}, {{0, 50}, {200, 50}}}, options),
      (std::vector<std::vector<int>>{{3}, {}}));
}

TEST(Undistortion, DistortedPixelOfInvertsUndistort) {
  const CameraIntrinsics camera = WideCamera();
  for (double u = -20.0; u <= 660.0; u += 34.0) {
    for (double v = -20.0; v <= 500.0; v += 26.0) {
      const Eigen::Vector2d p(u, v);
      EXPECT_NEAR((camera.Undistort(DistortedPixelOf(camera, p)) - p).norm(), 0.0, kRoundTripTolPx);
    }
  }
  // Barrel distortion: the distorted pixel is nearer the centre; no distortion: identity.
  const Eigen::Vector2d corner(0.0, 0.0);
  EXPECT_LT((DistortedPixelOf(camera, corner) - Eigen::Vector2d(320, 240)).norm(),
            (corner - Eigen::Vector2d(320, 240)).norm() - 5.0);
  EXPECT_EQ(DistortedPixelOf(camera.Undistorted(), corner), corner);
}

TEST(Undistortion, ImagedStraightLinesUndistortOntoTheLine) {
  // A straight undistorted line imaged through the distortion is a curve; any chord of the
  // curve (what a detector fits to a fragment) undistorts to points on the straight line.
  const CameraIntrinsics camera = WideCamera();
  const Segment2 line{{20.0, 30.0}, {600.0, 90.0}};
  std::vector<Eigen::Vector2d> curve;
  for (int k = 0; k <= 20; ++k)
    curve.push_back(DistortedPixelOf(camera, line.a + (line.b - line.a) * (k / 20.0)));
  // The curve bows: its middle is off the chord of its ends by several pixels.
  EXPECT_GT(DistanceToLine(curve[10], {curve[0], curve[20]}), 2.0);
  for (int k = 0; k + 5 <= 20; k += 5) {
    const Segment2 chord = UndistortSegment(camera, {curve[k], curve[k + 5]});
    EXPECT_LT(DistanceToLine(chord.a, line), kStraightTolPx);
    EXPECT_LT(DistanceToLine(chord.b, line), kStraightTolPx);
  }
}

TEST(Undistortion, RemapTablesSampleTheDistortedPixel) {
  const CameraIntrinsics camera = WideCamera();
  cv::Mat map1, map2, map_x, map_y;
  BuildUndistortionMaps(camera, camera.width, camera.height, &map1, &map2);
  cv::convertMaps(map1, map2, map_x, map_y, CV_32FC1);
  for (int v = 0; v < camera.height; v += 37) {
    for (int u = 0; u < camera.width; u += 41) {
      const Eigen::Vector2d q = DistortedPixelOf(camera, Eigen::Vector2d(u, v));
      EXPECT_NEAR(map_x.at<float>(v, u), q.x(), kRemapTolPx);
      EXPECT_NEAR(map_y.at<float>(v, u), q.y(), kRemapTolPx);
    }
  }
}

}  // namespace
}  // namespace linetrack
