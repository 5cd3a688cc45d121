#include "tracking/tracker/image_undistorter.h"

#include <opencv2/imgproc.hpp>

#include "models/errors.h"

namespace linetrack {

struct ImageUndistorter::Maps {
  cv::Mat xy;        // CV_16SC2: integer source pixel
  cv::Mat fraction;  // CV_16UC1: interpolation table index
};

ImageUndistorter::ImageUndistorter(const CameraIntrinsics& camera)
    : camera_(camera), undistorted_(camera.Undistorted()) {
  if (camera.width <= 0 || camera.height <= 0) {
    throw InputError("camera '" + camera.name + "': the image size is needed to undistort");
  }
  if (!camera.has_distortion) return;
  cv::Mat map_x(camera.height, camera.width, CV_32FC1);
  cv::Mat map_y(camera.height, camera.width, CV_32FC1);
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector2d source = camera.Distort(Eigen::Vector2d(u, v));
      map_x.at<float>(v, u) = static_cast<float>(source.x());
      map_y.at<float>(v, u) = static_cast<float>(source.y());
    }
  }
  maps_ = std::make_unique<Maps>();
  cv::convertMaps(map_x, map_y, maps_->xy, maps_->fraction, CV_16SC2);
  buffer_.resize(static_cast<unsigned>(camera.height), static_cast<unsigned>(camera.width));
}

ImageUndistorter::~ImageUndistorter() = default;
ImageUndistorter::ImageUndistorter(ImageUndistorter&&) noexcept = default;
ImageUndistorter& ImageUndistorter::operator=(ImageUndistorter&&) noexcept = default;

const vpImage<unsigned char>& ImageUndistorter::Apply(const vpImage<unsigned char>& distorted) {
  if (static_cast<int>(distorted.getWidth()) != camera_.width ||
      static_cast<int>(distorted.getHeight()) != camera_.height) {
    throw InputError("frame of " + std::to_string(distorted.getWidth()) + "x" +
                     std::to_string(distorted.getHeight()) + " pixels, the camera '" +
                     camera_.name + "' is " + std::to_string(camera_.width) + "x" +
                     std::to_string(camera_.height));
  }
  if (!maps_) return distorted;
  // Both images are wrapped without copies; pixels mapped from outside the frame are black.
  const cv::Mat source(camera_.height, camera_.width, CV_8UC1,
                       const_cast<unsigned char*>(distorted.bitmap));
  cv::Mat target(camera_.height, camera_.width, CV_8UC1, buffer_.bitmap);
  cv::remap(source, target, maps_->xy, maps_->fraction, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  return buffer_;
}

}  // namespace linetrack
