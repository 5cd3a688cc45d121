// Flags of the line extractor shared by `linetrack lines` and `linetrack localize --image`.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "matching/lines/line_extractor.h"
#include "models/camera.h"

namespace linetrack::app {

// The flag values, as given on the command line.
struct LineFlags {
  std::string camera_path, camera_name;  // camera_path empty: no undistortion
  std::string detector = LineDetectorName(LineExtractionOptions().detector);
  double min_length_px = LineExtractionOptions().min_length_px;
  std::string roi;  // "U,V,WIDTH,HEIGHT"
  bool no_merge = false;
  std::string undistortion = "endpoints";

  // The extractor options; throws InputError naming the flag at fault.
  LineExtractionOptions Options() const;
  // The camera file's camera (nullopt without --camera); throws InputError naming the file.
  std::optional<CameraIntrinsics> Camera() const;
};

// Registers --detector, --min-length, --roi, --no-merge, --undistort on `cmd`; with
// `with_camera` also --camera and --camera-name (localize has its own).
void AddLineFlags(CLI::App* cmd, LineFlags* flags, bool with_camera = true);

}  // namespace linetrack::app
