// Sub-pixel sampling of a grey image, shared by the tracker's edge searches.
#pragma once

#include <visp3/core/vpImage.h>

#include <Eigen/Core>

namespace linetrack {

// Bilinear interpolation of `image` at pixel p (u = column, v = row; integer coordinates are
// pixel centres); false outside the image.
inline bool SampleBilinear(const vpImage<unsigned char>& image, const Eigen::Vector2d& p,
                           double* value) {
  const double u = p.x(), v = p.y();
  if (!(u >= 0.0 && v >= 0.0 && u < image.getWidth() - 1.0 && v < image.getHeight() - 1.0)) {
    return false;
  }
  const unsigned u0 = static_cast<unsigned>(u), v0 = static_cast<unsigned>(v);
  const double fu = u - u0, fv = v - v0;
  const double top = (1.0 - fu) * image[v0][u0] + fu * image[v0][u0 + 1];
  const double bottom = (1.0 - fu) * image[v0 + 1][u0] + fu * image[v0 + 1][u0 + 1];
  *value = (1.0 - fv) * top + fv * bottom;
  return true;
}

}  // namespace linetrack
