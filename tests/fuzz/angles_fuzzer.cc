// libFuzzer target for the angles CSV of `calibrate-mount` (calibration/mount_file.h). Any input
// must either parse or throw an InputError naming the file; crashes, hangs, leaks and undefined
// behaviour are findings.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "calibration/mount_file.h"
#include "tests/fuzz/fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = linetrack::WriteFuzzFile(data, size, ".csv");
  try {
    linetrack::ReadAnglesCsv(path);
  } catch (const linetrack::InputError& e) {
    linetrack::ExpectNamesFile(e, path);
  }
  std::filesystem::remove(path);
  return 0;
}
