// The small pieces of calibration/ on exact inputs: board layout, option checks, the outlier
// rule, the cornerSubPix window rule, ViSP's kdu refit, the edge blur estimate on renders of
// known blur, and a blurred view rejected as such.
#include <gtest/gtest.h>

#include <cmath>

#include "calibration/calibrate.h"
#include "tests/support/synthetic_board.h"

namespace linetrack {
namespace {

constexpr double kBlurTolPx = 0.35;       // edge blur estimate against the rendered sigma
constexpr double kKduInverseRmsPx = 5.0;  // kdu vs the exact inverse of kud = -0.25 (RMS px)
constexpr double kExact = 1e-12;

CameraIntrinsics Camera(double kud) {
  CameraIntrinsics c;
  c.width = 640;
  c.height = 480;
  c.px = 550.0;
  c.py = 545.0;
  c.u0 = 322.5;
  c.v0 = 241.3;
  c.has_distortion = kud != 0.0;
  c.kud = kud;
  return c;
}

// A fronto-parallel-ish pose with the whole board in view.
Eigen::Isometry3d FrontPose() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(-0.1, -0.06, 0.45);
  return pose;
}

TEST(Pattern, BoardPointsAreRowMajorOnTheSquareGrid) {
  PatternSpec p;
  p.cols = 4;
  p.rows = 3;
  p.square = 0.03;
  const auto points = BoardPoints(p);
  ASSERT_EQ(points.size(), 12u);
  EXPECT_NEAR(points[1].x(), 0.03, kExact);  // along a row
  EXPECT_NEAR(points[4].y(), 0.03, kExact);  // next row
  EXPECT_NEAR(points[11].x(), 0.09, kExact);
  EXPECT_NEAR(points[11].y(), 0.06, kExact);
  EXPECT_EQ(points[11].z(), 0.0);
}

TEST(Pattern, CheckRefusesWhatCannotWork) {
  std::string why;
  PatternSpec p;
  EXPECT_TRUE(p.Check(&why)) << why;
  p.cols = p.rows = 6;
  EXPECT_FALSE(p.Check(&why));  // square chessboard: orientation ambiguous
  p.kind = PatternKind::kCircles;
  EXPECT_TRUE(p.Check(&why)) << why;
  p.square = -1.0;
  EXPECT_FALSE(p.Check(&why));
  p = PatternSpec();
  p.kind = PatternKind::kCharuco;
  p.marker = 0.03;  // larger than the square
  EXPECT_FALSE(p.Check(&why));
  p.marker = 0.0;
  p.dictionary = "DICT_9X9_1";
  EXPECT_FALSE(p.Check(&why));
  EXPECT_EQ(ParsePatternKind("circles"), PatternKind::kCircles);
  EXPECT_FALSE(ParsePatternKind("squares").has_value());
}

TEST(Outliers, WorstViewFarAboveTheMedianAndTheFloor) {
  // OpenCV's per-view errors of left01..left14 (left_intrinsics.yml): left02 is index 1.
  const std::vector<double> left = {0.193, 1.182, 0.173, 0.193, 0.160, 0.180, 0.231,
                                    0.242, 0.296, 0.167, 0.202, 0.381, 0.174};
  EXPECT_EQ(FindOutlierView(left, 3.0, 0.5), 1);
  std::vector<double> without = left;
  without.erase(without.begin() + 1);
  EXPECT_EQ(FindOutlierView(without, 3.0, 0.5), -1);
  EXPECT_EQ(FindOutlierView({0.01, 0.01, 0.012, 0.2}, 3.0, 0.5), -1);  // below the floor
  EXPECT_EQ(FindOutlierView({0.01, 0.01, 0.012, 0.2}, 3.0, 0.1), 3);
  EXPECT_EQ(FindOutlierView({0.5}, 3.0, 0.1), -1);
}

TEST(Detection, SubpixWindowNeverReachesTheNeighbourCorner) {
  EXPECT_EQ(SubpixHalfWindow(11, 60.0), 11);
  EXPECT_EQ(SubpixHalfWindow(11, 21.7), 11);  // left02's smallest spacing: unchanged
  EXPECT_EQ(SubpixHalfWindow(11, 14.4), 7);
  EXPECT_EQ(SubpixHalfWindow(11, 2.0), 2);
  EXPECT_EQ(SubpixHalfWindow(5, std::numeric_limits<double>::infinity()), 5);
}

// RMS over the image (pixels) of the undistorted pixel by kdu against the exact inverse of kud.
double UndistortionRmsPx(const CameraIntrinsics& c) {
  double sum = 0.0;
  int n = 0;
  for (double u = 0; u <= 640; u += 16) {
    for (double v = 0; v <= 480; v += 16, ++n) {
      const Eigen::Vector2d d((u - c.u0) / c.px, (v - c.v0) / c.py);
      Eigen::Vector2d x = d;  // solves d = x (1 + kud |x|^2)
      for (int k = 0; k < 100; ++k)
        x = d / (1.0 + c.kud * x.squaredNorm());
      const Eigen::Vector2d exact(c.u0 + c.px * x.x(), c.v0 + c.py * x.y());
      sum += (c.Undistort(Eigen::Vector2d(u, v)) - exact).squaredNorm();
    }
  }
  return std::sqrt(sum / n);
}

TEST(VispModel, FitKduIsTheBestOneTermInverseOfKud) {
  CameraIntrinsics c = Camera(-0.25);
  const double fitted = FitKdu(c);
  c.kdu = fitted;
  const double best = UndistortionRmsPx(c);
  EXPECT_LT(best, kKduInverseRmsPx);
  for (double other : {-c.kud, fitted - 0.01, fitted + 0.01}) {
    c.kdu = other;
    EXPECT_GT(UndistortionRmsPx(c), best) << other;
  }
  EXPECT_NEAR(FitKdu(Camera(0.0)), 0.0, kExact);
}

TEST(Detection, EdgeBlurEstimateFollowsTheRenderedBlur) {
  PatternSpec pattern;
  const CameraIntrinsics camera = Camera(0.0);
  for (double sigma : {1.0, 2.0, 3.0}) {
    BoardRenderOptions render;
    render.blur_sigma = sigma;
    const cv::Mat image = RenderBoard(pattern, camera, FrontPose(), render);
    const PatternDetection d = DetectPattern(image, pattern, DetectionOptions());
    ASSERT_TRUE(d.found) << "sigma " << sigma;
    // The pixel's own box (variance 1/12) adds to the rendered blur.
    EXPECT_NEAR(d.edge_blur_px, std::sqrt(sigma * sigma + 1.0 / 12.0), kBlurTolPx) << sigma;
  }
}

TEST(Calibrate, BlurredViewIsRejectedAsBlurred) {
  PatternSpec pattern;
  const CameraIntrinsics camera = Camera(-0.1);
  BoardRenderOptions render;
  const auto poses = RandomBoardPoses(pattern, camera, render, 4, 7);
  ASSERT_EQ(poses.size(), 4u);
  std::vector<CalibrationImage> images;
  for (size_t i = 0; i < poses.size(); ++i) {
    render.blur_sigma = i == 2 ? 3.5 : 0.0;
    images.push_back({"view" + std::to_string(i), RenderBoard(pattern, camera, poses[i], render)});
  }
  CalibrationOptions options;
  const CalibrationResult result = Calibrate(images, options);
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_EQ(result.views[2].status, ViewStatus::kBlurred) << result.views[2].reason;
  EXPECT_GT(result.views[2].detection.edge_blur_px, options.detection.max_edge_blur_px);
  EXPECT_EQ(result.UsedViews(), 3);
}

}  // namespace
}  // namespace linetrack
