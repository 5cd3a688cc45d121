// libFuzzer target for the camera files (models/camera_file.h): ViSP XML, OpenCV FileStorage
// (YAML or XML) and ROS camera_info YAML, told apart by their content. Any input must either
// give a camera or throw an InputError naming the file; crashes, hangs, leaks and undefined
// behaviour are findings.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "models/camera_file.h"
#include "tests/fuzz/fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = linetrack::WriteFuzzFile(data, size, ".cam");
  try {
    linetrack::ReadCameraFile(path);
  } catch (const linetrack::InputError& e) {
    linetrack::ExpectNamesFile(e, path);
  }
  std::filesystem::remove(path);
  return 0;
}
