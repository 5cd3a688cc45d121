// libFuzzer target for the .cao parser: any input must either parse or throw InputError;
// crashes, hangs, leaks and undefined behaviour are findings.
#include <cstddef>
#include <cstdint>
#include <string>

#include "models/cao_reader.h"
#include "tests/fuzz/fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    linetrack::ParseCao(text, "fuzz.cao", nullptr);
  } catch (const linetrack::InputError& e) {
    linetrack::ExpectNamesFile(e, "fuzz.cao");
  }
  return 0;
}
