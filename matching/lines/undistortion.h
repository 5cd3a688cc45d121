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

// Both endpoints of a segment measured in the distorted image, in undistorted pixels.
Segment2 UndistortSegment(const CameraIntrinsics& camera, const Segment2& distorted);

// Remapping tables for cv::remap (fixed-point CV_16SC2 + CV_16UC1): undistorted pixel (u, v) of
// a width x height image samples the distorted image at DistortedPixelOf(u, v).
void BuildUndistortionMaps(const CameraIntrinsics& camera, int width, int height, cv::Mat* map1,
                           cv::Mat* map2);

}  // namespace linetrack
