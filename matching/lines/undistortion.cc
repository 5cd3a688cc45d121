#include "matching/lines/undistortion.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace linetrack {

Eigen::Vector2d DistortedPixelOf(const CameraIntrinsics& camera, const Eigen::Vector2d& uv) {
  if (!camera.has_distortion || camera.kdu == 0.0) return uv;
  const double x = (uv.x() - camera.u0) / camera.px, y = (uv.y() - camera.v0) / camera.py;
  const double rho_u = std::hypot(x, y);
  if (rho_u == 0.0) return uv;
  // Solve rho_d (1 + kdu rho_d^2) = rho_u; increasing in rho_d while 1 + 3 kdu rho_d^2 > 0.
  double rho = rho_u;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const double f = rho * (1.0 + camera.kdu * rho * rho) - rho_u;
    const double slope = 1.0 + 3.0 * camera.kdu * rho * rho;
    if (slope <= 1e-6) break;
    const double step = f / slope;
    rho -= step;
    if (std::abs(step) < 1e-13) break;
  }
  const double scale = rho / rho_u;
  return {camera.u0 + camera.px * x * scale, camera.v0 + camera.py * y * scale};
}

Segment2 UndistortSegment(const CameraIntrinsics& camera, const Segment2& distorted) {
  return {camera.Undistort(distorted.a), camera.Undistort(distorted.b)};
}

void BuildUndistortionMaps(const CameraIntrinsics& camera, int width, int height, cv::Mat* map1,
                           cv::Mat* map2) {
  cv::Mat map_x(height, width, CV_32FC1), map_y(height, width, CV_32FC1);
  for (int v = 0; v < height; ++v) {
    float* mx = map_x.ptr<float>(v);
    float* my = map_y.ptr<float>(v);
    for (int u = 0; u < width; ++u) {
      const Eigen::Vector2d q = DistortedPixelOf(camera, Eigen::Vector2d(u, v));
      mx[u] = static_cast<float>(q.x());
      my[u] = static_cast<float>(q.y());
    }
  }
  cv::convertMaps(map_x, map_y, *map1, *map2, CV_16SC2);
}

}  // namespace linetrack
