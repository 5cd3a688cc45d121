// Agreement with published calibrations of OpenCV's sample images left01..left14 (no left10),
// extracted from Debian's opencv-doc by scripts/fetch_test_data.sh: OpenCV's own result
// left_intrinsics.yml (read from the file, not copied) and ViSP's calibration tutorial figures;
// left02 is the outlier view the default rejection drops. Also ViSP's 6x6 dot grids.
#include <gtest/gtest.h>

#include <opencv2/core/persistence.hpp>

#include <filesystem>
#include <string>

#include "calibration/calibrate.h"

namespace linetrack {
namespace {

namespace fs = std::filesystem;

constexpr double kOpenCvAgreementPx = 0.01;     // fx, fy, cx, cy against left_intrinsics.yml
constexpr double kOpenCvRmsAgreementPx = 1e-3;  // overall and per-view RMS errors
constexpr double kOpenCvDistortionAgreement = 1e-3;
// ViSP's tutorial prints 2 decimals (4 for kud, 3 for the error): half a unit of the last one.
constexpr double kVispRoundingPx = 0.005;
constexpr double kVispKudRounding = 0.00005;
constexpr double kVispErrorRoundingPx = 0.0005;
constexpr double kCircleGridMaxRmsPx = 0.35;
constexpr double kCircleGridFocalAgreement = 0.02;  // ViSP vs OpenCV focal length (relative)

const std::string kData = LINETRACK_TEST_DATA;
const char* const kLeftNames[] = {"left01", "left02", "left03", "left04", "left05",
                                  "left06", "left07", "left08", "left09", "left11",
                                  "left12", "left13", "left14"};

// Paths of OpenCV's sample images; fails the calling test when the data is missing.
std::vector<std::string> LeftImages() {
  std::vector<std::string> paths;
  for (const char* name : kLeftNames)
    paths.push_back(kData + "/opencv/" + name + ".jpg");
  return paths;
}

::testing::AssertionResult TestDataPresent() {
  for (const std::string& p : LeftImages()) {
    if (!fs::exists(p)) {
      return ::testing::AssertionFailure()
             << p << " is missing: run scripts/fetch_test_data.sh " << kData
             << " (scripts/test.sh does) or configure with -DLINETRACK_TEST_DATA=DIR";
    }
  }
  if (!fs::exists(kData + "/opencv/left_intrinsics.yml")) {
    return ::testing::AssertionFailure() << kData << "/opencv/left_intrinsics.yml is missing";
  }
  return ::testing::AssertionSuccess();
}

// Settings of OpenCV's calibration sample for left_intrinsics.yml: 9x6, 25 mm, -a 1 (flags 2:
// CALIB_FIX_ASPECT_RATIO, k3 free), all 13 views kept.
CalibrationOptions PublishedSettings() {
  CalibrationOptions options;
  options.opencv.fix_aspect_ratio = true;
  options.reject_outliers = false;
  return options;
}

class PublishedCalibration : public ::testing::Test {
 protected:
  // One calibration of the 13 views shared by the agreement tests (it takes seconds).
  static void SetUpTestSuite() {
    if (!TestDataPresent()) return;
    result_ =
        new CalibrationResult(Calibrate(LoadCalibrationImages(LeftImages()), PublishedSettings()));
  }
  static void TearDownTestSuite() {
    delete result_;
    result_ = nullptr;
  }
  void SetUp() override {
    ASSERT_TRUE(TestDataPresent());
    ASSERT_NE(result_, nullptr);
    ASSERT_TRUE(result_->ok()) << result_->message;
    ASSERT_EQ(result_->UsedViews(), 13);
  }
  static CalibrationResult* result_;
};

CalibrationResult* PublishedCalibration::result_ = nullptr;

TEST_F(PublishedCalibration, ReproducesOpenCvsLeftIntrinsics) {
  cv::FileStorage fs(kData + "/opencv/left_intrinsics.yml", cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  cv::Mat k, d, per_view;
  fs["camera_matrix"] >> k;
  fs["distortion_coefficients"] >> d;
  fs["per_view_reprojection_errors"] >> per_view;
  ASSERT_EQ(static_cast<int>(fs["flags"]), PublishedSettings().opencv.Flags());
  const OpenCvCalibration& m = result_->opencv;
  EXPECT_EQ(m.flags, static_cast<int>(fs["flags"]));
  EXPECT_NEAR(m.fx, k.at<double>(0, 0), kOpenCvAgreementPx);
  EXPECT_NEAR(m.fy, k.at<double>(1, 1), kOpenCvAgreementPx);
  EXPECT_NEAR(m.cx, k.at<double>(0, 2), kOpenCvAgreementPx);
  EXPECT_NEAR(m.cy, k.at<double>(1, 2), kOpenCvAgreementPx);
  for (int i = 0; i < 5; ++i)
    EXPECT_NEAR(m.distortion[static_cast<size_t>(i)], d.at<double>(i), kOpenCvDistortionAgreement);
  EXPECT_NEAR(m.rms, static_cast<double>(fs["avg_reprojection_error"]), kOpenCvRmsAgreementPx);
  ASSERT_EQ(per_view.total(), m.view_error.size());
  for (size_t i = 0; i < m.view_error.size(); ++i)
    EXPECT_NEAR(m.view_error[i], per_view.at<float>(static_cast<int>(i)), kOpenCvRmsAgreementPx);
}

TEST_F(PublishedCalibration, ReproducesVispsTutorialFigures) {
  // ViSP's calibration tutorial on the same 13 images (perspectiveProjWithDistortion).
  const CameraIntrinsics& c = result_->visp.with;
  EXPECT_NEAR(c.px, 536.98, kVispRoundingPx);
  EXPECT_NEAR(c.py, 537.42, kVispRoundingPx);
  EXPECT_NEAR(c.u0, 344.10, kVispRoundingPx);
  EXPECT_NEAR(c.v0, 235.18, kVispRoundingPx);
  EXPECT_NEAR(c.kud, -0.2673, kVispKudRounding);
  EXPECT_NEAR(result_->visp.global_error_with, 0.434, kVispErrorRoundingPx);
  // The refined model fits the pixels at least as well as ViSP's compromise.
  EXPECT_TRUE(result_->visp.refined);
  std::vector<int> counts(result_->visp.view_error_with.size(), 54);
  EXPECT_LE(result_->visp.rms_final, PooledRms(result_->visp.view_error_with, counts));
}

TEST(PublishedOutlier, DefaultRejectionDropsLeft02) {
  ASSERT_TRUE(TestDataPresent());
  CalibrationOptions options = PublishedSettings();
  options.reject_outliers = true;
  const CalibrationResult result = Calibrate(LoadCalibrationImages(LeftImages()), options);
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_EQ(result.rejection_rounds, 1);
  ASSERT_EQ(result.views.size(), 13u);
  for (const ViewReport& v : result.views) {
    if (v.name == "left02.jpg") {
      EXPECT_EQ(v.status, ViewStatus::kOutlier);
      EXPECT_NE(v.reason.find("median view error"), std::string::npos) << v.reason;
      EXPECT_GT(v.error_opencv, options.outlier_factor * 0.19);
    } else {
      EXPECT_EQ(v.status, ViewStatus::kUsed) << v.name << ": " << v.reason;
    }
  }
  EXPECT_LT(result.opencv.rms, 0.3);  // 0.39 with left02
}

TEST(PublishedCircleGrid, VispDotGridsCalibrate) {
  CalibrationOptions options;
  options.pattern.kind = PatternKind::kCircles;
  options.pattern.cols = options.pattern.rows = 6;
  options.pattern.square = 0.03;
  std::vector<std::string> paths;
  for (int i = 1; i <= 4; ++i)
    paths.push_back(std::string(VISP_IMAGES_DIR) + "/calibration/grid36-0" + std::to_string(i) +
                    ".pgm");
  const CalibrationResult result = Calibrate(LoadCalibrationImages(paths), options);
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_EQ(result.UsedViews(), 4);
  for (const ViewReport& v : result.views)
    EXPECT_EQ(v.detection.image_points.size(), 36u) << v.name;
  EXPECT_LT(result.visp.rms_final, kCircleGridMaxRmsPx);
  EXPECT_LT(result.opencv.rms, kCircleGridMaxRmsPx);
  EXPECT_NEAR(result.visp.final_model.px, result.opencv.fx,
              kCircleGridFocalAgreement * result.opencv.fx);
  EXPECT_NEAR(result.visp.final_model.py, result.opencv.fy,
              kCircleGridFocalAgreement * result.opencv.fy);
  std::printf(
      "grid36: ViSP px %.2f py %.2f u0 %.2f v0 %.2f kud %.4f RMS %.3f; OpenCV fx %.2f fy "
      "%.2f cx %.2f cy %.2f RMS %.3f\n",
      result.visp.final_model.px, result.visp.final_model.py, result.visp.final_model.u0,
      result.visp.final_model.v0, result.visp.final_model.kud, result.visp.rms_final,
      result.opencv.fx, result.opencv.fy, result.opencv.cx, result.opencv.cy, result.opencv.rms);
}

}  // namespace
}  // namespace linetrack
