// The whole calibration: detect the pattern in every image, drop blurred views, estimate ViSP's
// two models and OpenCV's model, reject outlier views (error far above the others) and
// re-estimate, and report every view's fate. docs/calibration.md describes the method.
#pragma once

#include <opencv2/core/mat.hpp>

#include <string>
#include <vector>

#include "calibration/detection.h"
#include "calibration/opencv_calibration.h"
#include "calibration/pattern.h"
#include "calibration/visp_calibration.h"

namespace linetrack {

// One input image: a name for reports and its 8-bit grey pixels.
struct CalibrationImage {
  std::string name;
  cv::Mat gray;  // CV_8UC1
};

// Reads image files as 8-bit grey. Throws InputError naming the file when the list is empty, a
// file cannot be read, or the sizes differ.
std::vector<CalibrationImage> LoadCalibrationImages(const std::vector<std::string>& paths);

struct CalibrationOptions {
  PatternSpec pattern;
  DetectionOptions detection;
  VispCalibrationOptions visp;
  OpenCvCalibrationOptions opencv;
  // Outlier views: the worst view is dropped while its RMS error (OpenCV model) exceeds both
  // outlier_factor times the median view error and outlier_min_error_px; then re-estimation.
  bool reject_outliers = true;
  double outlier_factor = 3.0;
  double outlier_min_error_px = 0.5;
  int min_views = 3;  // fewer usable views: the calibration is refused

  bool Check(std::string* why) const;
};

enum class ViewStatus { kUsed, kPatternNotFound, kBlurred, kOutlier };

// "used", "pattern not found", "blurred", "error outlier".
const char* ToString(ViewStatus status);

struct ViewReport {
  std::string name;
  ViewStatus status = ViewStatus::kPatternNotFound;
  std::string reason;  // why rejected, with the figures (empty when used)
  PatternDetection detection;
  // RMS reprojection errors (pixels) under each model; < 0 when the view was not estimated.
  double error_visp_without = -1.0, error_visp = -1.0, error_opencv = -1.0;
  int estimate_index = -1;  // index of the view in the final estimates (-1 when not used)
};

enum class CalibrationStatus {
  kOk,
  kPatternNeverFound,  // bad input: no image shows the pattern (wrong size or images?)
  kTooFewViews,        // bad input: fewer than min_views usable views
  kEstimationFailed,   // ViSP or OpenCV failed on usable views
};

struct CalibrationResult {
  CalibrationStatus status = CalibrationStatus::kEstimationFailed;
  std::string message;  // one line explaining a failure
  int width = 0, height = 0;
  std::vector<ViewReport> views;  // one per image, in input order
  VispCalibration visp;
  OpenCvCalibration opencv;
  int rejection_rounds = 0;  // re-estimations after dropping outliers

  bool ok() const { return status == CalibrationStatus::kOk; }
  int UsedViews() const;
};

// Detects the pattern in every image (first stage of Calibrate).
std::vector<PatternDetection> DetectAll(const std::vector<CalibrationImage>& images,
                                        const CalibrationOptions& options);

// Estimation from detections (names and detections in the same order; image size in pixels).
CalibrationResult CalibrateDetections(const std::vector<std::string>& names,
                                      const std::vector<PatternDetection>& detections, int width,
                                      int height, const CalibrationOptions& options);

// DetectAll then CalibrateDetections. Images must share one size (LoadCalibrationImages).
CalibrationResult Calibrate(const std::vector<CalibrationImage>& images,
                            const CalibrationOptions& options);

// Index of the view to drop as an outlier, or -1: the largest error when it exceeds both
// factor * median(errors) and min_error_px. Pure function of the per-view errors.
int FindOutlierView(const std::vector<double>& errors, double factor, double min_error_px);

// The outlier rule's settings are usable: factor finite and above 1, min_error_px finite and
// >= 0; otherwise false with *why naming the flag (--outlier-factor, --outlier-min-error).
bool CheckOutlierRule(double factor, double min_error_px, std::string* why);

}  // namespace linetrack
