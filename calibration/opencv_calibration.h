// OpenCV's calibrateCamera model for users of OpenCV-based tools: pinhole K = [fx 0 cx; 0 fy cy;
// 0 0 1] with the Brown-Conrady distortion (k1, k2, p1, p2, k3) applied to normalised
// coordinates, estimated from the same detections as the ViSP models.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "calibration/board_view.h"

namespace linetrack {

struct OpenCvCalibrationOptions {
  bool fix_aspect_ratio = false;  // CALIB_FIX_ASPECT_RATIO with fx / fy = 1
  bool zero_tangent = false;      // CALIB_ZERO_TANGENT_DIST
  bool fix_k3 = false;            // CALIB_FIX_K3

  // The calibrateCamera flags these options stand for.
  int Flags() const;
};

struct OpenCvCalibration {
  bool ok = false;
  std::string failure;
  int flags = 0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;  // pixels
  std::array<double, 5> distortion{};             // k1, k2, p1, p2, k3
  double rms = 0.0;                               // over all points (pixels), as returned
  std::vector<double> view_error;                 // per-view RMS (pixels)
  // Standard deviations of fx, fy, cx, cy, k1, k2, p1, p2, k3 (OpenCV's estimate).
  std::array<double, 9> std_dev{};
  std::vector<Eigen::Vector3d> rotation_vectors, translations;  // cam_from_board per view
};

// Calibrates from at least 3 views (image size in pixels); cv::Exception never escapes.
OpenCvCalibration CalibrateWithOpenCv(const std::vector<BoardView>& views, int width, int height,
                                      const OpenCvCalibrationOptions& options);

// Pixel of a board point under the OpenCV model and one view's pose (cv::projectPoints).
std::vector<Eigen::Vector2d> ProjectWithOpenCv(const OpenCvCalibration& model, size_t view,
                                               const std::vector<Eigen::Vector3d>& board_points);

}  // namespace linetrack
