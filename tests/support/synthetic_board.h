// Synthetic calibration images with an exact ground truth: a planar board (chessboard, circle
// grid or ChArUco) seen by a camera with ViSP's radial distortion (models/camera.h), rendered by
// ray casting every sub-pixel sample through the distortion onto the board plane (box-filter
// anti-aliasing), optionally blurred and noisy. Used by the tests and docs/calibration.md.
#pragma once

#include <opencv2/core/mat.hpp>

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "calibration/pattern.h"
#include "models/camera.h"

namespace linetrack {

struct BoardRenderOptions {
  int supersampling = 3;        // n x n samples per pixel
  double black = 30.0;          // grey level of dark squares and dots
  double white = 220.0;         // grey level of light squares and the board
  double background = 90.0;     // grey level off the board
  double margin_squares = 1.0;  // light border around the pattern, in squares
  double dot_radius = 0.3;      // circle grid: dot radius in units of the spacing
  double blur_sigma = 0.0;      // Gaussian blur after rendering (pixels; 0: none)
  double noise_sigma = 0.0;     // additive Gaussian noise (grey levels; 0: none)
  std::uint64_t seed = 1;       // noise seed

  bool Check(std::string* why) const;
};

// Renders the board seen from `cam_from_board` (ViSP camera axes, board frame of pattern.h) by a
// camera of size camera.width x camera.height (8-bit grey).
cv::Mat RenderBoard(const PatternSpec& pattern, const CameraIntrinsics& camera,
                    const Eigen::Isometry3d& cam_from_board, const BoardRenderOptions& options);

// Board outline in the board frame (metres): min and max corners of the light area.
Eigen::AlignedBox2d BoardExtent(const PatternSpec& pattern, const BoardRenderOptions& options);

// `count` random poses, seeded, from which the whole board (with its border) is inside the
// image with `border_px` to spare: distance 0.35-0.75 m scaled to the board, tilts up to
// 40 degrees about both board axes, roll up to 20 degrees.
std::vector<Eigen::Isometry3d> RandomBoardPoses(const PatternSpec& pattern,
                                                const CameraIntrinsics& camera,
                                                const BoardRenderOptions& options, int count,
                                                std::uint64_t seed, double border_px = 12.0);

}  // namespace linetrack
