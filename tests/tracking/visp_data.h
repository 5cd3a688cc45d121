// Paths and ground truth of the visp-images-data sequences the tracker is checked on.
#pragma once

#include <visp3/io/vpImageIo.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "tracking/tracker/pose_file.h"

namespace linetrack::testing {

// The ViSP-images folder (VISP_INPUT_IMAGE_PATH, else the Debian package's).
inline std::string VispImages() {
  const char* env = std::getenv("VISP_INPUT_IMAGE_PATH");
  return std::string(env ? env : "/usr/share/visp-images-data") + "/ViSP-images";
}

inline std::string CastleSimu() {
  return VispImages() + "/mbt-depth/Castle-simu";
}

// Frame `index` (1..40) of Castle-simu and its true cam_from_world (CameraPose/Camera_%03d.txt).
inline std::string CastleImage(int index) {
  char name[64];
  std::snprintf(name, sizeof(name), "/Images/Image_%04d.pgm", index);
  return CastleSimu() + name;
}
inline Eigen::Isometry3d CastleTruth(int index) {
  char name[64];
  std::snprintf(name, sizeof(name), "/CameraPose/Camera_%03d.txt", index);
  return ReadPoseFile(CastleSimu() + name);
}
constexpr int kCastleFrames = 40;

inline std::string Cube() {
  return VispImages() + "/mbt";
}
inline std::string CubeImage(int index) {
  char name[64];
  std::snprintf(name, sizeof(name), "/cube/image%04d.pgm", index);
  return Cube() + name;
}
constexpr int kCubeFrames = 218;

inline vpImage<unsigned char> ReadGrey(const std::string& path) {
  vpImage<unsigned char> image;
  vpImageIo::read(image, path);
  return image;
}

}  // namespace linetrack::testing
