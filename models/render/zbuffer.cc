#include "models/render/zbuffer.h"

#include <algorithm>
#include <cmath>

namespace linetrack {

bool PlaneInverseDepth(const Eigen::Vector3d& normal_cam, double offset_cam,
                       const SamplePinhole& pinhole, Eigen::Vector3d* coeffs) {
  const double px = pinhole.px, py = pinhole.py, u0 = pinhole.u0, v0 = pinhole.v0;
  // X = z (x, y, 1) with x = (i - u0) / px: n . X = d gives 1/z = n . (x, y, 1) / d.
  if (std::abs(offset_cam) < 1e-12) return false;
  const Eigen::Vector3d& n = normal_cam;
  *coeffs = Eigen::Vector3d(n.x() / px, n.y() / py, n.z() - n.x() * u0 / px - n.y() * v0 / py) /
            offset_cam;
  return true;
}

std::vector<Eigen::Vector3d> ClipPolygonNear(const std::vector<Eigen::Vector3d>& polygon,
                                             double near) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(polygon.size() + 2);
  for (size_t k = 0; k < polygon.size(); ++k) {
    const Eigen::Vector3d& a = polygon[k];
    const Eigen::Vector3d& b = polygon[(k + 1) % polygon.size()];
    const bool a_in = a.z() >= near, b_in = b.z() >= near;
    if (a_in) out.push_back(a);
    if (a_in != b_in) out.push_back(a + (near - a.z()) / (b.z() - a.z()) * (b - a));
  }
  return out;
}

void ZBuffer::Resize(int width, int height) {
  width_ = width;
  height_ = height;
  inv_depth_.resize(static_cast<size_t>(width) * height);
  ids_.resize(static_cast<size_t>(width) * height);
}

void ZBuffer::ClearToPlanes(const Eigen::Vector3d& coeffs_a, uint16_t id_a,
                            const Eigen::Vector3d& coeffs_b, uint16_t id_b) {
  for (int j = 0; j < height_; ++j) {
    float* depth = &inv_depth_[static_cast<size_t>(j) * width_];
    uint16_t* ids = &ids_[static_cast<size_t>(j) * width_];
    const float a0 = static_cast<float>(coeffs_a.y() * j + coeffs_a.z());
    const float b0 = static_cast<float>(coeffs_b.y() * j + coeffs_b.z());
    const float da = static_cast<float>(coeffs_a.x()), db = static_cast<float>(coeffs_b.x());
    for (int i = 0; i < width_; ++i) {
      const float a = a0 + da * i, b = b0 + db * i;
      const bool b_wins = b > a;
      const float best = b_wins ? b : a;
      depth[i] = best > 0.0f ? best : 0.0f;
      ids[i] = best > 0.0f ? (b_wins ? id_b : id_a) : kNoSurface;
    }
  }
}

void ZBuffer::FillPolygon(const std::vector<Eigen::Vector2d>& polygon,
                          const Eigen::Vector3d& coeffs, uint16_t id, Mode mode, float bias) {
  if (polygon.size() < 3) return;
  double y_min = polygon[0].y(), y_max = y_min;
  for (const Eigen::Vector2d& p : polygon) {
    y_min = std::min(y_min, p.y());
    y_max = std::max(y_max, p.y());
  }
  // Rows whose centre j lies in [y_min, y_max); a sample is covered when y_a <= j < y_b on an edge.
  const int j_begin = std::max(0, static_cast<int>(std::ceil(y_min)));
  const int j_end = std::min(height_, static_cast<int>(std::ceil(y_max)));
  const float ci = static_cast<float>(coeffs.x());
  for (int j = j_begin; j < j_end; ++j) {
    crossings_.clear();
    for (size_t k = 0; k < polygon.size(); ++k) {
      const Eigen::Vector2d& a = polygon[k];
      const Eigen::Vector2d& b = polygon[(k + 1) % polygon.size()];
      if ((a.y() <= j) == (b.y() <= j)) continue;
      crossings_.push_back(a.x() + (j - a.y()) / (b.y() - a.y()) * (b.x() - a.x()));
    }
    std::sort(crossings_.begin(), crossings_.end());
    const float row0 = static_cast<float>(coeffs.y() * j + coeffs.z());
    float* depth = &inv_depth_[static_cast<size_t>(j) * width_];
    uint16_t* ids = &ids_[static_cast<size_t>(j) * width_];
    for (size_t k = 0; k + 1 < crossings_.size(); k += 2) {
      // Samples i with x_a <= i < x_b (clamped to the row).
      const int i_begin = static_cast<int>(std::max(0.0, std::ceil(crossings_[k])));
      const int i_end = static_cast<int>(std::min<double>(width_, std::ceil(crossings_[k + 1])));
      if (mode == Mode::kNearest) {
        for (int i = i_begin; i < i_end; ++i) {
          const float z = row0 + ci * i;
          if (z > depth[i]) {
            depth[i] = z;
            ids[i] = id;
          }
        }
      } else {
        for (int i = i_begin; i < i_end; ++i) {
          const float z = row0 + ci * i;
          if (std::abs(z - depth[i]) <= bias * depth[i]) ids[i] = id;
        }
      }
    }
  }
}

}  // namespace linetrack
