#include "app/line_flags.h"

#include <sstream>

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
    std::stringstream in(roi);
    std::string field;
    int values[4];
    int n = 0;
    while (std::getline(in, field, ',')) {
      size_t used = 0;
      try {
        if (n < 4) values[n] = std::stoi(field, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (n >= 4 || used != field.size() || field.empty()) n = 5;
      ++n;
    }
    if (n != 4 || values[0] < 0 || values[1] < 0 || values[2] <= 0 || values[3] <= 0) {
      throw InputError("--roi: expected U,V,WIDTH,HEIGHT (pixels, size > 0), got '" + roi + "'");
    }
    options.roi = {values[0], values[1], values[2], values[3]};
  }
  std::string why;
  if (!options.Check(&why)) throw InputError("--min-length/--roi: " + why);
  return options;
}

std::optional<CameraIntrinsics> LineFlags::Camera() const {
  if (camera_path.empty()) return std::nullopt;
  return ReadCameraXml(camera_path, camera_name);
}

void AddLineFlags(CLI::App* cmd, LineFlags* flags, bool with_camera) {
  if (with_camera) {
    cmd->add_option("--camera", flags->camera_path,
                    "ViSP camera XML: segments are undistorted with its radial model");
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
