#include "matching/lines/undistortion.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace linetrack {

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
