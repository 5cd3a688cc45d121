// One calibration view: the board points seen in one image and where they were detected.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace linetrack {

struct BoardView {
  std::string name;                           // image file name (for reports)
  std::vector<Eigen::Vector3d> board_points;  // board frame, metres (z = 0)
  std::vector<Eigen::Vector2d> image_points;  // pixels (u = column, v = row)
};

// Root mean square of the distances |a_k - b_k| (pixels); 0 for empty lists.
double RmsDistance(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b);

// Root mean square over all points of several views, from per-view RMS values and point counts:
// sqrt(sum n_i e_i^2 / sum n_i).
double PooledRms(const std::vector<double>& view_rms, const std::vector<int>& counts);

}  // namespace linetrack
