// libFuzzer target for ViSP's pose files (tracking/tracker/pose_file.h): a pose vector or a 4x4
// matrix. Any input must either parse or throw an InputError naming the file; crashes, hangs,
// leaks and undefined behaviour are findings.
#include <cstddef>
#include <cstdint>
#include <string>

#include "tests/fuzz/fuzz_check.h"
#include "tracking/tracker/pose_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    linetrack::ParsePoseText(text, "fuzz.0.pos");
  } catch (const linetrack::InputError& e) {
    linetrack::ExpectNamesFile(e, "fuzz.0.pos");
  }
  return 0;
}
