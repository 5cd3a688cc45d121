// Round trips of a camera through each file `linetrack calibrate` writes (ViSP XML, OpenCV YAML,
// ROS camera_info) and back through ReadCamera, which recognises each by its content.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "calibration/output_files.h"
#include "models/camera_file.h"
#include "models/errors.h"

namespace linetrack {
namespace {

constexpr double kTextTol = 1e-9;      // intrinsics through text (17 significant digits or more)
constexpr double kXmlTol = 1e-6;       // ViSP's XML writer keeps about 10 significant digits
constexpr double kXmlPixelTol = 1e-3;  // the same pixel distorted by two files' cameras
constexpr double kTextPixelTol = 1e-6;

// A calibration result holding both models of one camera (OpenCV's with k1 only, so that ViSP's
// one-term model can stand for it exactly).
CalibrationResult Result(double k1) {
  CalibrationResult result;
  result.status = CalibrationStatus::kOk;
  result.width = 640;
  result.height = 480;
  OpenCvCalibration& cv = result.opencv;
  cv.ok = true;
  cv.fx = 551.123456789;
  cv.fy = 548.987654321;
  cv.cx = 322.5;
  cv.cy = 241.25;
  cv.distortion = {k1, 0.0, 0.0, 0.0, 0.0};
  VispCalibration& visp = result.visp;
  visp.ok = true;
  visp.without.px = cv.fx;
  visp.without.py = cv.fy;
  visp.without.u0 = cv.cx;
  visp.without.v0 = cv.cy;
  visp.without.width = result.width;
  visp.without.height = result.height;
  visp.final_model = visp.without;
  visp.final_model.has_distortion = true;
  visp.final_model.kud = k1;
  visp.final_model.kdu = -0.9 * k1;
  return result;
}

class CameraFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(LINETRACK_BINARY_DIR) / "test_output" / "CameraFilesTest";
    std::filesystem::create_directories(dir_);
  }
  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  std::filesystem::path dir_;
};

TEST_F(CameraFilesTest, ViSPXmlRoundTrip) {
  const CalibrationResult result = Result(-0.2);
  const std::string path = Write("camera.xml", VispCameraXml(result, {}, "front"));
  const CameraFile file = ReadCameraFile(path, "front");
  EXPECT_EQ(file.format, CameraFileFormat::kVispXml);
  const CameraIntrinsics& c = file.camera;
  const CameraIntrinsics& expected = result.visp.final_model;
  EXPECT_EQ(c.name, "front");
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 480);
  EXPECT_NEAR(c.px, expected.px, kXmlTol);
  EXPECT_NEAR(c.py, expected.py, kXmlTol);
  EXPECT_NEAR(c.u0, expected.u0, kXmlTol);
  EXPECT_NEAR(c.v0, expected.v0, kXmlTol);
  EXPECT_TRUE(c.has_distortion);
  EXPECT_NEAR(c.kud, expected.kud, kXmlTol);
  EXPECT_NEAR(c.kdu, expected.kdu, kXmlTol);
}

// The OpenCV and ROS files of `result` read back as one camera with OpenCV's intrinsics.
void ExpectOpenCvModel(const CameraFile& file, const CalibrationResult& result) {
  const OpenCvCalibration& cv = result.opencv;
  EXPECT_EQ(file.camera.width, result.width);
  EXPECT_EQ(file.camera.height, result.height);
  EXPECT_NEAR(file.camera.px, cv.fx, kTextTol);
  EXPECT_NEAR(file.camera.py, cv.fy, kTextTol);
  EXPECT_NEAR(file.camera.u0, cv.cx, kTextTol);
  EXPECT_NEAR(file.camera.v0, cv.cy, kTextTol);
  EXPECT_NEAR(file.brown_conrady.k1, cv.distortion[0], kTextTol);
  const double k1 = cv.distortion[0];
  EXPECT_EQ(file.camera.has_distortion, k1 != 0.0);
  EXPECT_NEAR(file.camera.kud, k1, kTextTol);  // k1 alone: ViSP's kud is the same model
  EXPECT_LT(file.approximation_px, kTextTol);
}

TEST_F(CameraFilesTest, OpenCvYamlRoundTrip) {
  for (const double k1 : {0.0, -0.2}) {
    const CalibrationResult result = Result(k1);
    const std::string path = Write("opencv.yml", OpenCvYaml(result, {}));
    const CameraFile file = ReadCameraFile(path);
    EXPECT_EQ(file.format, CameraFileFormat::kOpenCv);
    ExpectOpenCvModel(file, result);
  }
}

TEST_F(CameraFilesTest, RosCameraInfoRoundTrip) {
  for (const double k1 : {0.0, -0.2}) {
    const CalibrationResult result = Result(k1);
    const std::string path = Write("camera_info.yaml", RosCameraInfoYaml(result, "front"));
    const CameraFile file = ReadCameraFile(path, "front");
    EXPECT_EQ(file.format, CameraFileFormat::kRosCameraInfo);
    EXPECT_EQ(file.camera.name, "front");
    ExpectOpenCvModel(file, result);
  }
}

TEST_F(CameraFilesTest, TheThreeFilesAgreeOnPixels) {
  // The same camera from each file maps the same undistorted pixel to the same distorted one.
  const CalibrationResult result = Result(-0.2);
  const CameraIntrinsics xml = ReadCamera(Write("a.xml", VispCameraXml(result, {}, "front")));
  const CameraIntrinsics yml = ReadCamera(Write("a.yml", OpenCvYaml(result, {})));
  const CameraIntrinsics ros = ReadCamera(Write("a.yaml", RosCameraInfoYaml(result, "front")));
  for (const Eigen::Vector2d& uv : {Eigen::Vector2d(10.0, 12.0), Eigen::Vector2d(600.0, 400.0)}) {
    EXPECT_LT((xml.Distort(uv) - yml.Distort(uv)).norm(), kXmlPixelTol);
    EXPECT_LT((yml.Distort(uv) - ros.Distort(uv)).norm(), kTextPixelTol);
  }
}

TEST_F(CameraFilesTest, RefusesOtherFilesAndMissingNames) {
  auto error_of = [](const std::string& path, const std::string& name) {
    try {
      ReadCameraFile(path, name);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string text = Write("notes.txt", "just some notes\n");
  EXPECT_NE(error_of(text, "").find("notes.txt: not a camera file"), std::string::npos);
  const std::string ros = Write("b.yaml", RosCameraInfoYaml(Result(0.0), "front"));
  EXPECT_NE(error_of(ros, "rear").find("no camera named 'rear'"), std::string::npos);
  const std::string yml = Write("b.yml", OpenCvYaml(Result(0.0), {}));
  EXPECT_NE(error_of(yml, "rear").find("one unnamed camera"), std::string::npos);
}

}  // namespace
}  // namespace linetrack
