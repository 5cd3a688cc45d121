// `linetrack localize --image`: the image's line segments for the matcher, and the overlay of
// the answer (matched model edges projected with the found pose in green, unmatched detections
// in red, a text box with the pose, the correspondences and the times).
#pragma once

#include <visp3/core/vpImage.h>
#include <optional>
#include <string>
#include <vector>

#include "app/line_flags.h"
#include "matching/localizer.h"
#include "models/camera.h"
#include "models/wireframe.h"

namespace linetrack::app {

// An image with its extracted segments.
struct ImageLines {
  vpImage<unsigned char> image;
  CameraIntrinsics camera;         // the camera file's model (with its distortion)
  std::vector<Segment2> segments;  // undistorted pixels
  std::string detector;
  double ms = 0.0;  // extraction time
};

// Reads the image and extracts its segments with the camera of `camera_path`. Throws
// InputError naming the file when the image cannot be read, is empty or has another size.
ImageLines ExtractImageLines(const std::string& image_path, const std::string& camera_path,
                             const std::string& camera_name, const LineFlags& flags);

// The overlay PNG (file content) of a localisation from `lines`.
std::string LocalizationOverlayPng(const ImageLines& lines, const WireframeModel& model,
                                   const LocalizationResult& result, double matcher_ms);

}  // namespace linetrack::app
