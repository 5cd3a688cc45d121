// Cameras from OpenCV and ROS files: the Brown-Conrady model against OpenCV's own projection, its
// inverse, the one-term fit that stands for it, and the parsers on the files' text.
#include "models/camera_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/calib3d.hpp>

#include "models/errors.h"

namespace linetrack {
namespace {

constexpr double kExactTol = 1e-12;    // normalised coordinates, exact formulas
constexpr double kPixelTol = 1e-9;     // pixels, values that pass through text
constexpr double kFitSlopeTol = 1e-6;  // relative cost difference of equal steps off the minimum

// OpenCV's sample calibration (left_intrinsics.yml of OpenCV's samples).
constexpr double kFx = 535.91573396163199, kCx = 342.28315473308373, kCy = 235.57082909788173;
const BrownConrady kSampleDistortion{-0.26637260909660682, -0.038588898922304653,
                                     1.7831947042852964e-03, -2.8122100441115472e-04,
                                     0.23839153080878486};

CameraIntrinsics Pinhole() {
  CameraIntrinsics camera;
  camera.width = 640;
  camera.height = 480;
  camera.px = camera.py = kFx;
  camera.u0 = kCx;
  camera.v0 = kCy;
  return camera;
}

TEST(CameraFile, BrownConradyDistortsAsOpenCvProjects) {
  const BrownConrady& d = kSampleDistortion;
  const cv::Matx33d k(kFx, 0, kCx, 0, kFx, kCy, 0, 0, 1);
  const std::vector<double> coefficients = {d.k1, d.k2, d.p1, d.p2, d.k3};
  for (const Eigen::Vector2d& x : {Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(-0.55, 0.41),
                                   Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.6, 0.45)}) {
    std::vector<cv::Point2d> projected;
    cv::projectPoints(std::vector<cv::Point3d>{{x.x(), x.y(), 1.0}}, cv::Vec3d(0, 0, 0),
                      cv::Vec3d(0, 0, 0), k, coefficients, projected);
    const Eigen::Vector2d x_d = d.Distort(x);
    EXPECT_NEAR(kCx + kFx * x_d.x(), projected[0].x, kPixelTol);
    EXPECT_NEAR(kCy + kFx * x_d.y(), projected[0].y, kPixelTol);
  }
}

TEST(CameraFile, UndistortInvertsDistort) {
  for (const Eigen::Vector2d& x : {Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(-0.55, 0.41)}) {
    const std::optional<Eigen::Vector2d> back =
        kSampleDistortion.Undistort(kSampleDistortion.Distort(x));
    ASSERT_TRUE(back.has_value());
    EXPECT_LT((*back - x).norm(), kExactTol);
  }
}

TEST(CameraFile, OneTermFitIsExactForARadialK1) {
  const double k1 = -0.21;
  const OneTermFit fit = FitOneTermDistortion(Pinhole(), BrownConrady{k1, 0, 0, 0, 0});
  EXPECT_NEAR(fit.kud, k1, kExactTol);
  EXPECT_LT(fit.max_error_px, kPixelTol);
  // kdu is the inverse's best single term: same sign as -kud, and it nearly undoes kud.
  EXPECT_GT(fit.kdu, 0.0);
}

// The fit's cost at kud + delta, as FitOneTermDistortion defines it.
double ForwardCost(const CameraIntrinsics& pinhole, const BrownConrady& d, double kud) {
  double cost = 0.0;
  for (int a = 0; a <= 40; ++a) {
    for (int b = 0; b <= 40; ++b) {
      const Eigen::Vector2d x_d((pinhole.width * a / 40.0 - pinhole.u0) / pinhole.px,
                                (pinhole.height * b / 40.0 - pinhole.v0) / pinhole.py);
      const std::optional<Eigen::Vector2d> x = d.Undistort(x_d);
      if (!x) continue;
      const Eigen::Vector2d e = *x * (1.0 + kud * x->squaredNorm()) - x_d;
      cost += std::pow(pinhole.px * e.x(), 2) + std::pow(pinhole.py * e.y(), 2);
    }
  }
  return cost;
}

TEST(CameraFile, OneTermFitIsTheLeastSquaresMinimum) {
  const OneTermFit fit = FitOneTermDistortion(Pinhole(), kSampleDistortion);
  const double step = 1e-4;
  const double at = ForwardCost(Pinhole(), kSampleDistortion, fit.kud);
  const double below = ForwardCost(Pinhole(), kSampleDistortion, fit.kud - step);
  const double above = ForwardCost(Pinhole(), kSampleDistortion, fit.kud + step);
  EXPECT_LT(at, below);
  EXPECT_LT(at, above);
  // A parabola: the slope at the minimum is zero, so both sides rise alike.
  EXPECT_NEAR((above - below) / at, 0.0, kFitSlopeTol);
  EXPECT_GT(fit.max_error_px, 0.1);  // k2, k3 and the tangential terms are not one term
  EXPECT_TRUE(std::isfinite(fit.max_error_px));
}

const char* const kOpenCvText = R"(%YAML:1.0
---
image_width: 640
image_height: 480
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 535.91573396163199, 0., 342.28315473308373, 0., 535.91573396163199,
       235.57082909788173, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 5
   cols: 1
   dt: d
   data: [ -0.21, 0., 0., 0., 0. ]
)";

TEST(CameraFile, ParsesAnOpenCvFile) {
  const CameraFile file = ParseOpenCvCamera(kOpenCvText, "left.yml");
  EXPECT_EQ(file.format, CameraFileFormat::kOpenCv);
  EXPECT_EQ(file.camera.width, 640);
  EXPECT_EQ(file.camera.height, 480);
  EXPECT_NEAR(file.camera.px, kFx, kPixelTol);
  EXPECT_NEAR(file.camera.py, kFx, kPixelTol);
  EXPECT_NEAR(file.camera.u0, kCx, kPixelTol);
  EXPECT_NEAR(file.camera.v0, kCy, kPixelTol);
  EXPECT_TRUE(file.camera.has_distortion);
  EXPECT_NEAR(file.camera.kud, -0.21, kExactTol);
  EXPECT_LT(file.approximation_px, kPixelTol);
}

const char* const kRosText = R"(image_width: 640
image_height: 480
camera_name: narrow_stereo
camera_matrix:
  rows: 3
  cols: 3
  data: [535.91573396163199, 0, 342.28315473308373, 0, 535.91573396163199, 235.57082909788173, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [0, 0, 0, 0, 0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [535.91573396163199, 0, 342.28315473308373, 0, 0, 535.91573396163199, 235.57082909788173, 0, 0, 0, 1, 0]
)";

TEST(CameraFile, ParsesARosCameraInfo) {
  const CameraFile file = ParseRosCameraInfo(kRosText, "camera_info.yaml");
  EXPECT_EQ(file.format, CameraFileFormat::kRosCameraInfo);
  EXPECT_EQ(file.camera.name, "narrow_stereo");
  EXPECT_EQ(file.camera.width, 640);
  EXPECT_NEAR(file.camera.px, kFx, kPixelTol);
  EXPECT_NEAR(file.camera.v0, kCy, kPixelTol);
  EXPECT_FALSE(file.camera.has_distortion);
  EXPECT_EQ(file.approximation_px, 0.0);
}

// The InputError message of `parse`, or "" when it does not throw.
template <typename Parse>
std::string ErrorOf(Parse parse) {
  try {
    parse();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CameraFile, RefusesWhatItCannotRepresent) {
  std::string ros = kRosText;
  ros.replace(ros.find("plumb_bob"), 9, "equidistant");
  ros.replace(ros.find("[0, 0, 0, 0, 0]"), 15, "[0.1, 0, 0, 0]");
  EXPECT_NE(ErrorOf([&] { ParseRosCameraInfo(ros, "c.yaml"); }).find("equidistant"),
            std::string::npos);
  std::string no_matrix = kOpenCvText;
  no_matrix.replace(no_matrix.find("camera_matrix"), 13, "other_matrix");
  EXPECT_NE(ErrorOf([&] { ParseOpenCvCamera(no_matrix, "c.yml"); }).find("c.yml: no camera_matrix"),
            std::string::npos);
  std::string not_pinhole = kRosText;
  not_pinhole.replace(not_pinhole.find(", 0, 0, 1]"), 10, ", 0, 1, 1]");
  EXPECT_NE(ErrorOf([&] { ParseRosCameraInfo(not_pinhole, "c.yaml"); }).find("camera_matrix"),
            std::string::npos);
  EXPECT_NE(
      ErrorOf([&] { ParseRosCameraInfo("camera_matrix: [1, 2", "c.yaml"); }).find("malformed YAML"),
      std::string::npos);
}

// Sizes are checked before OpenCV allocates them; a binary file is refused before any parser.
TEST(CameraFile, RefusesMatricesWhoseSizeDoesNotMatchTheirData) {
  std::string huge = kOpenCvText;
  huge.replace(huge.find("rows: 3"), 7, "rows: 2000000000");
  EXPECT_NE(
      ErrorOf([&] { ParseOpenCvCamera(huge, "c.yml"); }).find("camera_matrix: 2000000000 x 3"),
      std::string::npos);
  std::string short_data = kOpenCvText;
  short_data.replace(short_data.find("rows: 5"), 7, "rows: 6");
  EXPECT_NE(ErrorOf([&] {
              ParseOpenCvCamera(short_data, "c.yml");
            }).find("distortion_coefficients: 6 x 1 does not match its 5 values"),
            std::string::npos);
  const std::string path = ::testing::TempDir() + "binary_camera.yml";
  std::ofstream(path) << std::string("%YAML:1.0\n\0\0", 13);
  EXPECT_NE(ErrorOf([&] { ReadCameraFile(path); }).find("a NUL byte at offset 10"),
            std::string::npos);
}

}  // namespace
}  // namespace linetrack
