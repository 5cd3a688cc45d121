// ViSP's radial distortion model (models/camera.h) applied to line-extraction results: segment
// endpoints from a distorted image mapped to undistorted pixels, and the remapping tables that
// turn a distorted image into an undistorted one. Straight world lines are straight only in
// undistorted pixels.
#pragma once

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "models/camera.h"
#include "models/geometry.h"

namespace linetrack {

// The distorted pixel q with camera.Undistort(q) = uv: the exact inverse of the kdu model
// (x_u = x_d (1 + kdu r_d^2) in normalised coordinates), solved radially by Newton's method.
// This is what the renderer draws (output pixel q shows undistorted pixel Undistort(q)); ViSP's
// kud model is only an approximate inverse. Identity without distortion.
Eigen::Vector2d DistortedPixelOf(const CameraIntrinsics& camera, const Eigen::Vector2d& uv);

// Both endpoints of a segment measured in the distorted image, in undistorted pixels.
Segment2 UndistortSegment(const CameraIntrinsics& camera, const Segment2& distorted);

// Remapping tables for cv::remap (fixed-point CV_16SC2 + CV_16UC1): undistorted pixel (u, v) of
// a width x height image samples the distorted image at DistortedPixelOf(u, v).
void BuildUndistortionMaps(const CameraIntrinsics& camera, int width, int height, cv::Mat* map1,
                           cv::Mat* map2);

}  // namespace linetrack
