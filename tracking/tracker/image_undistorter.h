// Undistortion of grey frames before tracking (ViSP's tracker expects undistorted images), with
// a map precomputed once per camera, so a frame costs one bilinear remap (OpenCV's fixed-point
// cv::remap; vpImageTools::undistort copies its maps on every call, docs/tracking.md). Without
// distortion the frame is passed through untouched.
#pragma once

#include <visp3/core/vpImage.h>

#include <memory>

#include "models/camera.h"

namespace linetrack {

class ImageUndistorter {
 public:
  // `camera` gives the image size and its distortion (ViSP's model: the undistorted pixel p
  // shows the distorted image at CameraIntrinsics::Distort(p), kud). Throws InputError when the
  // size is unknown.
  explicit ImageUndistorter(const CameraIntrinsics& camera);
  ~ImageUndistorter();
  ImageUndistorter(ImageUndistorter&&) noexcept;
  ImageUndistorter& operator=(ImageUndistorter&&) noexcept;

  // The undistorted image of `distorted` (a reference to an internal buffer, valid until the next
  // call, or to `distorted` itself when the camera has no distortion). Throws InputError when the
  // frame's size differs from the camera's.
  const vpImage<unsigned char>& Apply(const vpImage<unsigned char>& distorted);

  // The model of the undistorted image (same focal lengths and centre, no distortion).
  const CameraIntrinsics& undistorted_camera() const { return undistorted_; }
  bool passthrough() const { return !camera_.has_distortion; }

 private:
  CameraIntrinsics camera_;
  CameraIntrinsics undistorted_;
  struct Maps;                  // OpenCV fixed-point maps (kept out of this header)
  std::unique_ptr<Maps> maps_;  // null without distortion
  vpImage<unsigned char> buffer_;
};

}  // namespace linetrack
