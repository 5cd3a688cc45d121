#include "calibration/calibrate.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "models/errors.h"
#include "models/statistics.h"

namespace linetrack {
namespace {

std::string Format(const char* format, double a, double b = 0.0, double c = 0.0) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), format, a, b, c);
  return buffer;
}

}  // namespace

const char* ToString(ViewStatus status) {
  switch (status) {
    case ViewStatus::kUsed:
      return "used";
    case ViewStatus::kPatternNotFound:
      return "pattern not found";
    case ViewStatus::kBlurred:
      return "blurred";
    case ViewStatus::kOutlier:
      return "error outlier";
  }
  return "?";
}

std::vector<CalibrationImage> LoadCalibrationImages(const std::vector<std::string>& paths) {
  if (paths.empty()) throw InputError("no calibration images given (or the pattern matched none)");
  std::vector<CalibrationImage> images;
  for (const std::string& path : paths) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
      throw InputError(Located(path, 0, "no such image file"));
    }
    CalibrationImage image;
    image.name = std::filesystem::path(path).filename().string();
    try {
      image.gray = cv::imread(path, cv::IMREAD_GRAYSCALE);
    } catch (const cv::Exception&) {
      image.gray.release();
    }
    if (image.gray.empty()) throw InputError(Located(path, 0, "cannot read the image"));
    if (!images.empty() && image.gray.size() != images.front().gray.size()) {
      throw InputError(Located(path, 0,
                               "image size " + std::to_string(image.gray.cols) + "x" +
                                   std::to_string(image.gray.rows) + " differs from " +
                                   images.front().name + " (" +
                                   std::to_string(images.front().gray.cols) + "x" +
                                   std::to_string(images.front().gray.rows) + ")"));
    }
    images.push_back(std::move(image));
  }
  return images;
}

bool CheckOutlierRule(double factor, double min_error_px, std::string* why) {
  if (!(factor > 1.0) || !std::isfinite(factor)) {
    *why = "--outlier-factor must be a finite number above 1";
    return false;
  }
  if (!(min_error_px >= 0.0) || !std::isfinite(min_error_px)) {
    *why = "--outlier-min-error must be a finite number >= 0";
    return false;
  }
  return true;
}

bool CalibrationOptions::Check(std::string* why) const {
  if (!pattern.Check(why) || !detection.Check(why) || !visp.Check(why)) return false;
  if (!CheckOutlierRule(outlier_factor, outlier_min_error_px, why)) return false;
  if (min_views < 3) {
    *why = "at least 3 views are needed to calibrate";
    return false;
  }
  return true;
}

int CalibrationResult::UsedViews() const {
  return static_cast<int>(std::count_if(views.begin(), views.end(), [](const ViewReport& v) {
    return v.status == ViewStatus::kUsed;
  }));
}

int FindOutlierView(const std::vector<double>& errors, double factor, double min_error_px) {
  if (errors.size() < 2) return -1;
  const auto worst = std::max_element(errors.begin(), errors.end());
  const double median = Median(errors);
  if (*worst > factor * median && *worst > min_error_px) {
    return static_cast<int>(worst - errors.begin());
  }
  return -1;
}

std::vector<PatternDetection> DetectAll(const std::vector<CalibrationImage>& images,
                                        const CalibrationOptions& options) {
  std::vector<PatternDetection> detections;
  for (const CalibrationImage& image : images)
    detections.push_back(DetectPattern(image.gray, options.pattern, options.detection));
  return detections;
}

CalibrationResult CalibrateDetections(const std::vector<std::string>& names,
                                      const std::vector<PatternDetection>& detections, int width,
                                      int height, const CalibrationOptions& options) {
  CalibrationResult result;
  result.width = width;
  result.height = height;
  const std::vector<Eigen::Vector3d> board = BoardPoints(options.pattern);
  int found = 0;
  for (size_t i = 0; i < detections.size(); ++i) {
    ViewReport view;
    view.name = i < names.size() ? names[i] : "view " + std::to_string(i);
    view.detection = detections[i];
    if (!view.detection.found) {
      view.status = ViewStatus::kPatternNotFound;
      view.reason = "pattern not found";
    } else if (view.detection.edge_blur_px > options.detection.max_edge_blur_px) {
      ++found;
      view.status = ViewStatus::kBlurred;
      view.reason = Format("edge blur %.2f px above the limit %.2f px", view.detection.edge_blur_px,
                           options.detection.max_edge_blur_px);
    } else {
      ++found;
      view.status = ViewStatus::kUsed;
    }
    result.views.push_back(std::move(view));
  }
  if (found == 0) {
    result.status = CalibrationStatus::kPatternNeverFound;
    result.message = PatternNeverFoundMessage(options.pattern, detections.size());
    return result;
  }
  while (true) {
    std::vector<BoardView> views;
    std::vector<size_t> used;
    for (size_t i = 0; i < result.views.size(); ++i) {
      if (result.views[i].status != ViewStatus::kUsed) continue;
      used.push_back(i);
      views.push_back(ViewOfDetection(result.views[i].name, result.views[i].detection, board));
    }
    if (static_cast<int>(views.size()) < options.min_views) {
      result.status = CalibrationStatus::kTooFewViews;
      result.message = "only " + std::to_string(views.size()) + " usable views of " +
                       std::to_string(detections.size()) + " images (at least " +
                       std::to_string(options.min_views) + " needed)";
      return result;
    }
    result.visp = CalibrateWithVisp(views, width, height, options.visp);
    result.opencv = CalibrateWithOpenCv(views, width, height, options.opencv);
    if (!result.visp.ok || !result.opencv.ok) {
      result.status = CalibrationStatus::kEstimationFailed;
      result.message = !result.visp.ok ? result.visp.failure : result.opencv.failure;
      return result;
    }
    for (size_t k = 0; k < used.size(); ++k) {
      ViewReport& v = result.views[used[k]];
      v.estimate_index = static_cast<int>(k);
      v.error_visp_without = result.visp.view_error_without[k];
      v.error_visp = result.visp.view_error_final[k];
      v.error_opencv = result.opencv.view_error[k];
    }
    const int outlier = options.reject_outliers
                            ? FindOutlierView(result.opencv.view_error, options.outlier_factor,
                                              options.outlier_min_error_px)
                            : -1;
    if (outlier < 0 || static_cast<int>(views.size()) <= options.min_views) break;
    ViewReport& v = result.views[used[static_cast<size_t>(outlier)]];
    v.status = ViewStatus::kOutlier;
    v.estimate_index = -1;
    v.reason = Format("RMS error %.3f px above %.1f x the median view error %.3f px",
                      v.error_opencv, options.outlier_factor, Median(result.opencv.view_error));
    ++result.rejection_rounds;
  }
  // Errors of views that were dropped stay those of the last estimate that used them.
  result.status = CalibrationStatus::kOk;
  return result;
}

CalibrationResult Calibrate(const std::vector<CalibrationImage>& images,
                            const CalibrationOptions& options) {
  std::vector<std::string> names;
  for (const CalibrationImage& image : images)
    names.push_back(image.name);
  const int width = images.empty() ? 0 : images.front().gray.cols;
  const int height = images.empty() ? 0 : images.front().gray.rows;
  return CalibrateDetections(names, DetectAll(images, options), width, height, options);
}

}  // namespace linetrack
