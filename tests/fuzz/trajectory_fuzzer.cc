// libFuzzer target for the trajectory files (models/trajectory_io.h): each input is parsed as a
// TUM trajectory and as a prior CSV file. Either parse must succeed or throw an InputError naming
// the file; crashes, hangs, leaks and undefined behaviour are findings.
#include <cstddef>
#include <cstdint>
#include <string>

#include "models/trajectory_io.h"
#include "tests/fuzz/fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    linetrack::ParseTum(text, "fuzz.tum");
  } catch (const linetrack::InputError& e) {
    linetrack::ExpectNamesFile(e, "fuzz.tum");
  }
  try {
    linetrack::ParsePriors(text, "fuzz-prior.csv");
  } catch (const linetrack::InputError& e) {
    linetrack::ExpectNamesFile(e, "fuzz-prior.csv");
  }
  return 0;
}
