// A z-buffer over a grid of image samples holding, per sample, the inverse depth (1 / z_cam) and
// the id of the nearest surface; planar polygons are clipped against the near plane and
// scan-converted exactly (sample centres at integer coordinates, half-open coverage rule).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace linetrack {

// A pinhole in sample units: sample (i, j) = (u0 + px X / Z, v0 + py Y / Z).
struct SamplePinhole {
  double px = 0.0, py = 0.0, u0 = 0.0, v0 = 0.0;
};

// Inverse depth of a plane n . X = d (camera frame) as an affine function of the sample
// coordinates (i, j): 1/z = c.x i + c.y j + c.z. False when the plane passes through the optical
// centre (seen edge-on).
bool PlaneInverseDepth(const Eigen::Vector3d& normal_cam, double offset_cam,
                       const SamplePinhole& pinhole, Eigen::Vector3d* coeffs);

// Sutherland-Hodgman clipping of a polygon (camera frame) to the half-space z >= near.
std::vector<Eigen::Vector3d> ClipPolygonNear(const std::vector<Eigen::Vector3d>& polygon,
                                             double near);

class ZBuffer {
 public:
  static constexpr uint16_t kNoSurface = 0xffff;

  // How a polygon is written. kNearest: where it is nearer than the stored surface.
  // kDecal: where the stored surface lies at the polygon's depth within a relative `bias`
  // (markings painted on a surface); the stored depth is kept.
  enum class Mode { kNearest, kDecal };

  void Resize(int width, int height);
  int width() const { return width_; }
  int height() const { return height_; }

  // Fills every sample with the nearer of two planes (inverse-depth coefficients as in
  // PlaneInverseDepth; `id_b` wins where it is nearer); samples where neither lies in front of
  // the camera get kNoSurface and inverse depth 0.
  void ClearToPlanes(const Eigen::Vector3d& coeffs_a, uint16_t id_a,
                     const Eigen::Vector3d& coeffs_b, uint16_t id_b);

  // Scan-converts a polygon given in sample coordinates (any simple polygon, even-odd rule).
  void FillPolygon(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector3d& coeffs,
                   uint16_t id, Mode mode, float bias = 0.0f);

  uint16_t id(int i, int j) const { return ids_[static_cast<size_t>(j) * width_ + i]; }
  float inverse_depth(int i, int j) const {
    return inv_depth_[static_cast<size_t>(j) * width_ + i];
  }
  const uint16_t* id_row(int j) const { return &ids_[static_cast<size_t>(j) * width_]; }

 private:
  int width_ = 0, height_ = 0;
  std::vector<float> inv_depth_;
  std::vector<uint16_t> ids_;
  std::vector<double> crossings_;  // scratch for FillPolygon
};

}  // namespace linetrack
