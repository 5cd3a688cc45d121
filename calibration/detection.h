// Pattern detection with OpenCV: chessboard corners (findChessboardCorners + cornerSubPix, or
// findChessboardCornersSB), symmetric circle grids (findCirclesGrid), ChArUco corners (aruco
// markers + interpolateCornersCharuco); and an estimate of how blurred the pattern's edges are.
#pragma once

#include <opencv2/core/mat.hpp>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calibration/board_view.h"
#include "calibration/pattern.h"

namespace linetrack {

// Settings of the detectors. The defaults are those of OpenCV's calibration sample and ViSP's
// calibration tutorial: findChessboardCorners(ADAPTIVE_THRESH | FAST_CHECK | NORMALIZE_IMAGE),
// cornerSubPix with an 11x11 half window, 30 iterations, epsilon 0.1 px.
struct DetectionOptions {
  bool chessboard_sb = false;     // findChessboardCornersSB instead (no cornerSubPix)
  int subpix_half_window = 11;    // cornerSubPix winSize (the window is 2 n + 1 pixels wide)
  int subpix_iterations = 30;     // cornerSubPix TermCriteria COUNT
  double subpix_epsilon = 0.1;    // cornerSubPix TermCriteria EPS (pixels)
  int charuco_min_corners = 8;    // fewer ChArUco corners: the view is "not found"
  double max_edge_blur_px = 2.5;  // views whose edge blur estimate exceeds this are "blurred"

  bool Check(std::string* why) const;
};

// What the detector found in one image. Points in pixels (u = column, v = row, pixel centres at
// integer coordinates as OpenCV has them), point_ids index BoardPoints(pattern).
struct PatternDetection {
  bool found = false;
  std::vector<Eigen::Vector2d> image_points;
  std::vector<int> point_ids;
  double edge_blur_px = 0.0;  // EstimateEdgeBlur over the pattern (0 when not found)
};

// The cornerSubPix half window used for a board whose nearest corners are `min_spacing_px`
// apart: the configured one, shrunk to round(spacing / 2) (at least 2) so that the window never
// takes in the neighbouring corners, which would pull the corner off by pixels.
int SubpixHalfWindow(int configured, double min_spacing_px);

// The view a detection gives: its points and the board points of their ids (`board` =
// BoardPoints(pattern)), named `name`.
BoardView ViewOfDetection(const std::string& name, const PatternDetection& detection,
                          const std::vector<Eigen::Vector3d>& board);

// Detects `pattern` in an 8-bit grey image. Throws cv::Exception only on OpenCV faults.
PatternDetection DetectPattern(const cv::Mat& gray, const PatternSpec& pattern,
                               const DetectionOptions& options);

// Gaussian blur (standard deviation, pixels) of the edges inside the polygon of `points`'
// convex hull, from a blurred step's peak slope: a step of height h blurred by sigma has slope
// h / (sqrt(2 pi) sigma) at its centre, so sigma = (p95 - p5) / (sqrt(2 pi) g99) with the
// intensity percentiles p5, p95 and the 99th percentile g99 of the gradient magnitude (central
// differences, corrected for their own smoothing). Contrast and scale invariant.
double EstimateEdgeBlur(const cv::Mat& gray, const std::vector<Eigen::Vector2d>& points);

}  // namespace linetrack
