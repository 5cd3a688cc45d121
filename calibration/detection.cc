#include "calibration/detection.h"

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "models/statistics.h"

namespace linetrack {
namespace {

constexpr int kMinBlurPixels = 100;  // fewer pixels inside the pattern: no blur estimate

std::vector<Eigen::Vector2d> ToEigen(const std::vector<cv::Point2f>& points) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(points.size());
  for (const cv::Point2f& p : points)
    out.emplace_back(p.x, p.y);
  return out;
}

std::vector<int> AllIds(int count) {
  std::vector<int> ids(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i)
    ids[static_cast<size_t>(i)] = i;
  return ids;
}

// Smallest distance between grid neighbours (pixels) of corners ordered row by row.
double MinCornerSpacing(const std::vector<cv::Point2f>& corners, int cols, int rows) {
  double spacing = std::numeric_limits<double>::infinity();
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < cols; ++j) {
      const cv::Point2f& p = corners[static_cast<size_t>(i * cols + j)];
      if (j + 1 < cols)
        spacing = std::min(spacing, cv::norm(p - corners[static_cast<size_t>(i * cols + j + 1)]));
      if (i + 1 < rows)
        spacing = std::min(spacing, cv::norm(p - corners[static_cast<size_t>((i + 1) * cols + j)]));
    }
  }
  return spacing;
}

bool DetectChessboard(const cv::Mat& gray, const PatternSpec& pattern,
                      const DetectionOptions& options, std::vector<cv::Point2f>* corners) {
  const cv::Size size(pattern.cols, pattern.rows);
  if (options.chessboard_sb) {
    return cv::findChessboardCornersSB(
        gray, size, *corners,
        cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY);
  }
  const bool found = cv::findChessboardCorners(
      gray, size, *corners,
      cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_FAST_CHECK | cv::CALIB_CB_NORMALIZE_IMAGE);
  if (!found) return false;
  const int w = SubpixHalfWindow(options.subpix_half_window,
                                 MinCornerSpacing(*corners, pattern.cols, pattern.rows));
  cv::cornerSubPix(gray, *corners, cv::Size(w, w), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT,
                                    options.subpix_iterations, options.subpix_epsilon));
  return true;
}

// ChArUco corners and their ids (id = row * cols + col, as OpenCV numbers them).
bool DetectCharuco(const cv::Mat& gray, const PatternSpec& pattern, const DetectionOptions& options,
                   std::vector<cv::Point2f>* corners, std::vector<int>* ids) {
  const cv::Ptr<cv::aruco::Dictionary> dictionary =
      cv::aruco::getPredefinedDictionary(ArucoDictionaryId(pattern.dictionary));
  const cv::Ptr<cv::aruco::CharucoBoard> board = cv::aruco::CharucoBoard::create(
      pattern.cols + 1, pattern.rows + 1, static_cast<float>(pattern.square),
      static_cast<float>(pattern.MarkerSide()), dictionary);
  std::vector<std::vector<cv::Point2f>> marker_corners;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(gray, dictionary, marker_corners, marker_ids);
  if (marker_ids.size() < 2) return false;
  cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, gray, board, *corners, *ids);
  if (static_cast<int>(ids->size()) < options.charuco_min_corners) return false;
  // Collinear corners say nothing about a homography: ask for two rows and two columns at least.
  std::set<int> rows, cols;
  for (int id : *ids) {
    rows.insert(id / pattern.cols);
    cols.insert(id % pattern.cols);
  }
  return rows.size() >= 2 && cols.size() >= 2;
}

}  // namespace

int SubpixHalfWindow(int configured, double min_spacing_px) {
  if (!std::isfinite(min_spacing_px)) return configured;
  const long half_spacing = std::lround(0.5 * min_spacing_px);
  return static_cast<int>(std::clamp<long>(half_spacing, 2, configured));
}

bool DetectionOptions::Check(std::string* why) const {
  if (subpix_half_window < 1 || subpix_half_window > 50) {
    *why = "cornerSubPix half window must be within [1, 50] pixels";
    return false;
  }
  if (subpix_iterations < 1 || !(subpix_epsilon > 0.0) || !std::isfinite(subpix_epsilon)) {
    *why = "cornerSubPix needs at least one iteration and a positive epsilon";
    return false;
  }
  if (charuco_min_corners < 4) {
    *why = "a ChArUco view needs at least 4 corners";
    return false;
  }
  if (!(max_edge_blur_px > 0.0)) {
    *why = "--max-blur must be positive";
    return false;
  }
  return true;
}

BoardView ViewOfDetection(const std::string& name, const PatternDetection& detection,
                          const std::vector<Eigen::Vector3d>& board) {
  BoardView view;
  view.name = name;
  view.image_points = detection.image_points;
  for (int id : detection.point_ids)
    view.board_points.push_back(board[static_cast<size_t>(id)]);
  return view;
}

PatternDetection DetectPattern(const cv::Mat& gray, const PatternSpec& pattern,
                               const DetectionOptions& options) {
  PatternDetection detection;
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  switch (pattern.kind) {
    case PatternKind::kChessboard:
      detection.found = DetectChessboard(gray, pattern, options, &corners);
      ids = AllIds(pattern.PointCount());
      break;
    case PatternKind::kCircles:
      detection.found = cv::findCirclesGrid(gray, cv::Size(pattern.cols, pattern.rows), corners,
                                            cv::CALIB_CB_SYMMETRIC_GRID);
      ids = AllIds(pattern.PointCount());
      break;
    case PatternKind::kCharuco:
      detection.found = DetectCharuco(gray, pattern, options, &corners, &ids);
      break;
  }
  if (!detection.found || corners.size() != ids.size()) {
    detection.found = false;
    return detection;
  }
  detection.image_points = ToEigen(corners);
  detection.point_ids = std::move(ids);
  detection.edge_blur_px = EstimateEdgeBlur(gray, detection.image_points);
  return detection;
}

double EstimateEdgeBlur(const cv::Mat& gray, const std::vector<Eigen::Vector2d>& points) {
  if (points.size() < 3 || gray.empty() || gray.type() != CV_8UC1) return 0.0;
  std::vector<cv::Point> polygon, hull;
  for (const Eigen::Vector2d& p : points)
    polygon.emplace_back(static_cast<int>(std::lround(p.x())),
                         static_cast<int>(std::lround(p.y())));
  cv::convexHull(polygon, hull);
  cv::Mat mask = cv::Mat::zeros(gray.size(), CV_8U);
  cv::fillConvexPoly(mask, hull, cv::Scalar(255));
  cv::erode(mask, mask, cv::Mat());  // central differences need both neighbours inside
  std::vector<float> intensity, slope;
  for (int r = 1; r + 1 < gray.rows; ++r) {
    const unsigned char* m = mask.ptr<unsigned char>(r);
    const unsigned char* g = gray.ptr<unsigned char>(r);
    const unsigned char* up = gray.ptr<unsigned char>(r - 1);
    const unsigned char* down = gray.ptr<unsigned char>(r + 1);
    for (int c = 1; c + 1 < gray.cols; ++c) {
      if (!m[c]) continue;
      const float gx = 0.5f * (static_cast<float>(g[c + 1]) - static_cast<float>(g[c - 1]));
      const float gy = 0.5f * (static_cast<float>(down[c]) - static_cast<float>(up[c]));
      intensity.push_back(g[c]);
      slope.push_back(std::sqrt(gx * gx + gy * gy));
    }
  }
  if (static_cast<int>(intensity.size()) < kMinBlurPixels) return 0.0;
  const double height = QuantileLowerRank(intensity, 0.95) - QuantileLowerRank(intensity, 0.05);
  const double peak = QuantileLowerRank(slope, 0.99);
  if (!(peak > 0.0)) return 0.0;
  const double raw = height / (std::sqrt(2.0 * M_PI) * peak);
  // A central difference averages the slope over two pixels (a box of variance 1/3).
  return std::sqrt(std::max(0.0, raw * raw - 1.0 / 3.0));
}

}  // namespace linetrack
