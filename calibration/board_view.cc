#include "calibration/board_view.h"

#include <cmath>

namespace linetrack {

double RmsDistance(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b) {
  if (a.empty() || a.size() != b.size()) return 0.0;
  double sum = 0.0;
  for (size_t i = 0; i < a.size(); ++i)
    sum += (a[i] - b[i]).squaredNorm();
  return std::sqrt(sum / static_cast<double>(a.size()));
}

double PooledRms(const std::vector<double>& view_rms, const std::vector<int>& counts) {
  double sum = 0.0, n = 0.0;
  for (size_t i = 0; i < view_rms.size() && i < counts.size(); ++i) {
    sum += counts[i] * view_rms[i] * view_rms[i];
    n += counts[i];
  }
  return n > 0.0 ? std::sqrt(sum / n) : 0.0;
}

}  // namespace linetrack
