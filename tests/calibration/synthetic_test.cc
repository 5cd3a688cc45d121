// Calibration against an exact ground truth: boards rendered by ray casting through a known
// camera with ViSP's radial distortion (tests/support/synthetic_board.h) from 15 seeded random
// poses, detected and calibrated as real images are; the recovered intrinsics are compared with
// the truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "calibration/calibrate.h"
#include "tests/support/synthetic_board.h"

namespace linetrack {
namespace {

constexpr double kIntrinsicsRelTol = 1e-3;  // px, py, u0, v0 within 0.1 %
// ChArUco corners (interpolateCornersCharuco) are noisier: RMS 0.125 px against 0.06 px.
constexpr double kCharucoRelTol = 3e-3;
constexpr double kKudTol = 0.003;          // ViSP's kud (truth -0.22)
constexpr double kVispOwnRelTol = 5e-3;    // ViSP's estimate before the refinement
constexpr double kDistortionTolPx = 0.25;  // OpenCV's radial displacement vs the truth
constexpr double kStdDevCoverage = 4.0;    // truth within 4 reported standard deviations
constexpr double kMaxRmsPx = 0.15;         // reprojection RMS on clean renders
constexpr int kViews = 15;
constexpr std::uint64_t kSeed = 20240611;

CameraIntrinsics TruthCamera() {
  CameraIntrinsics c;
  c.width = 640;
  c.height = 480;
  c.px = 550.0;
  c.py = 545.0;
  c.u0 = 322.5;
  c.v0 = 241.3;
  c.has_distortion = true;
  c.kud = -0.22;
  return c;
}

std::vector<CalibrationImage> RenderViews(const PatternSpec& pattern,
                                          const CameraIntrinsics& camera, int count,
                                          std::uint64_t seed, BoardRenderOptions render) {
  std::vector<CalibrationImage> images;
  const auto poses = RandomBoardPoses(pattern, camera, render, count, seed);
  for (size_t i = 0; i < poses.size(); ++i) {
    render.seed = seed + i;
    const std::string name = "synthetic_" + std::to_string(100 + i).substr(1) + ".png";
    images.push_back({name, RenderBoard(pattern, camera, poses[i], render)});
  }
  return images;
}

// Largest |r_d(estimated) - r_d(truth)| * px over the radii the detected points cover, for
// OpenCV's radial model r_d = r (1 + k1 r^2 + k2 r^4 + k3 r^6) against the truth r (1 + kud r^2).
double RadialDisagreementPx(const OpenCvCalibration& m, const CameraIntrinsics& truth,
                            const CalibrationResult& result) {
  double r_max = 0.0;  // distorted radius bounds the undistorted one for barrel distortion
  for (const ViewReport& v : result.views) {
    for (const Eigen::Vector2d& p : v.detection.image_points)
      r_max =
          std::max(r_max, std::hypot((p.x() - truth.u0) / truth.px, (p.y() - truth.v0) / truth.py));
  }
  double worst = 0.0;
  for (int k = 0; k <= 100; ++k) {
    const double r = r_max * k / 100.0, r2 = r * r;
    const auto& d = m.distortion;
    const double est = r * (1.0 + d[0] * r2 + d[1] * r2 * r2 + d[4] * r2 * r2 * r2);
    worst = std::max(worst, std::abs(est - r * (1.0 + truth.kud * r2)) * truth.px);
  }
  return worst;
}

void ExpectIntrinsics(const CameraIntrinsics& got, const CameraIntrinsics& truth, double tol) {
  EXPECT_NEAR(got.px, truth.px, tol * truth.px);
  EXPECT_NEAR(got.py, truth.py, tol * truth.py);
  EXPECT_NEAR(got.u0, truth.u0, tol * truth.u0);
  EXPECT_NEAR(got.v0, truth.v0, tol * truth.v0);
}

std::string Describe(const CalibrationResult& r) {
  std::string text;
  for (const ViewReport& v : r.views)
    text += v.name + ": " + ToString(v.status) + " " + v.reason + "\n";
  const CameraIntrinsics& w = r.visp.with;
  const CameraIntrinsics& f = r.visp.final_model;
  char line[512];
  std::snprintf(line, sizeof(line),
                "ViSP px %.3f py %.3f u0 %.3f v0 %.3f kud %.5f; final px %.3f py %.3f u0 %.3f v0 "
                "%.3f kud %.5f kdu %.5f rms %.3f (std %.3f %.3f %.3f %.3f %.5f); OpenCV fx %.3f "
                "fy %.3f cx %.3f cy %.3f k1 %.4f k2 %.4f k3 %.4f rms %.3f\n",
                w.px, w.py, w.u0, w.v0, w.kud, f.px, f.py, f.u0, f.v0, f.kud, f.kdu,
                r.visp.rms_final, r.visp.std_dev(0), r.visp.std_dev(1), r.visp.std_dev(2),
                r.visp.std_dev(3), r.visp.std_dev(4), r.opencv.fx, r.opencv.fy, r.opencv.cx,
                r.opencv.cy, r.opencv.distortion[0], r.opencv.distortion[1], r.opencv.distortion[4],
                r.opencv.rms);
  return text + line;
}

// Checks the final ViSP model and OpenCV's model against the truth.
void ExpectRecovered(const CalibrationResult& result, const CameraIntrinsics& truth, double tol) {
  SCOPED_TRACE(Describe(result));
  const std::string summary = Describe(result);
  std::printf("%s", summary.substr(summary.rfind("ViSP px")).c_str());  // figures for the docs
  const CameraIntrinsics& f = result.visp.final_model;
  EXPECT_TRUE(result.visp.refined);
  ExpectIntrinsics(f, truth, tol);
  EXPECT_NEAR(f.kud, truth.kud, kKudTol);
  EXPECT_LT(result.visp.rms_final, kMaxRmsPx);
  const Eigen::Matrix<double, 5, 1> error(f.px - truth.px, f.py - truth.py, f.u0 - truth.u0,
                                          f.v0 - truth.v0, f.kud - truth.kud);
  for (int k = 0; k < 5; ++k) {
    EXPECT_GT(result.visp.std_dev(k), 0.0);
    EXPECT_LT(std::abs(error(k)), kStdDevCoverage * result.visp.std_dev(k)) << "parameter " << k;
  }
  // ViSP's own estimate before refinement: biased by its kud/kdu compromise, within 0.5 %.
  const CameraIntrinsics& w = result.visp.with;
  EXPECT_NEAR(w.px, truth.px, kVispOwnRelTol * truth.px);
  EXPECT_NEAR(w.u0, truth.u0, kVispOwnRelTol * truth.u0);
  const OpenCvCalibration& cv = result.opencv;
  CameraIntrinsics opencv = truth;
  opencv.px = cv.fx;
  opencv.py = cv.fy;
  opencv.u0 = cv.cx;
  opencv.v0 = cv.cy;
  ExpectIntrinsics(opencv, truth, tol);
  EXPECT_LT(RadialDisagreementPx(cv, truth, result), kDistortionTolPx);
  EXPECT_LT(cv.rms, kMaxRmsPx);
}

TEST(SyntheticCalibration, ChessboardRecoversTheTruth) {
  const CameraIntrinsics truth = TruthCamera();
  CalibrationOptions options;  // 9x6, 25 mm, outlier rejection on
  BoardRenderOptions render;
  render.noise_sigma = 1.0;
  const auto images = RenderViews(options.pattern, truth, kViews, kSeed, render);
  ASSERT_EQ(images.size(), static_cast<size_t>(kViews));
  const CalibrationResult result = Calibrate(images, options);
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_EQ(result.UsedViews(), kViews) << Describe(result);  // no outlier on clean renders
  ExpectRecovered(result, truth, kIntrinsicsRelTol);
}

TEST(SyntheticCalibration, CharucoRecoversTheTruth) {
  const CameraIntrinsics truth = TruthCamera();
  CalibrationOptions options;
  options.pattern.kind = PatternKind::kCharuco;
  options.pattern.cols = 7;  // 8 x 6 squares
  options.pattern.rows = 5;
  options.pattern.square = 0.03;
  BoardRenderOptions render;
  render.noise_sigma = 1.0;
  render.margin_squares = 0.5;
  const auto images = RenderViews(options.pattern, truth, kViews, kSeed + 1, render);
  ASSERT_EQ(images.size(), static_cast<size_t>(kViews));
  const CalibrationResult result = Calibrate(images, options);
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_GE(result.UsedViews(), kViews - 1) << Describe(result);
  ExpectRecovered(result, truth, kCharucoRelTol);
}

}  // namespace
}  // namespace linetrack
