#include "app/line_flags.h"

#include <cmath>

#include "app/cli_common.h"

#include "models/errors.h"

namespace linetrack::app {

LineExtractionOptions LineFlags::Options() const {
  LineExtractionOptions options;
  const auto kind = ParseLineDetector(detector);
  if (!kind) {
    throw InputError("--detector: unknown detector '" + detector + "' (hough, lsd, fld, edlines)");
  }
  options.detector = *kind;
  options.min_length_px = min_length_px;
  options.fragment_min_length_px = std::min(options.fragment_min_length_px, min_length_px);
  options.merge = !no_merge;
  if (undistortion == "image") {
    options.undistortion = UndistortionMode::kImage;
  } else if (undistortion != "endpoints") {
    throw InputError("--undistort: expected endpoints or image, got '" + undistortion + "'");
  }
  if (!roi.empty()) {
    const std::vector<double> v = ParseNumbers(roi, 4, "--roi");
    for (double x : v) {
      if (x != std::floor(x) || x < 0.0 || x > 1e6) {
        throw InputError("--roi: expected U,V,WIDTH,HEIGHT in whole pixels, got '" + roi + "'");
      }
    }
    if (v[2] <= 0.0 || v[3] <= 0.0) throw InputError("--roi: the size must be positive");
    options.roi = {static_cast<int>(v[0]), static_cast<int>(v[1]), static_cast<int>(v[2]),
                   static_cast<int>(v[3])};
  }
  std::string why;
  if (!options.Check(&why)) throw InputError("--min-length/--roi: " + why);
  return options;
}

std::optional<CameraIntrinsics> LineFlags::Camera() const {
  if (camera_path.empty()) return std::nullopt;
  return LoadCamera(camera_path, camera_name);
}

void AddLineFlags(CLI::App* cmd, LineFlags* flags, bool with_camera) {
  if (with_camera) {
    cmd->add_option(
        "--camera", flags->camera_path,
        "Camera file (ViSP XML, OpenCV or ROS YAML): segments are undistorted with its model");
    cmd->add_option("--camera-name", flags->camera_name, "Camera name in the XML (default: first)");
  }
  cmd->add_option("--detector", flags->detector, "Line detector: hough, lsd, fld, edlines")
      ->capture_default_str();
  cmd->add_option("--min-length", flags->min_length_px, "Shortest segment kept (pixels)")
      ->capture_default_str();
  cmd->add_option("--roi", flags->roi, "Region of interest U,V,WIDTH,HEIGHT (pixels)");
  cmd->add_flag("--no-merge", flags->no_merge, "Keep collinear fragments apart");
  cmd->add_option("--undistort", flags->undistortion,
                  "endpoints (undistort the segments) or image (remap the image first)")
      ->capture_default_str();
}

}  // namespace linetrack::app
