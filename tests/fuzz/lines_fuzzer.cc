// libFuzzer target for the line CSV of `localize --lines`, `heading` and `views`
// (app/lines_csv.h). Any text must either parse into finite segments or throw an InputError naming
// the file; crashes, hangs, leaks and undefined behaviour are findings.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "app/lines_csv.h"
#include "tests/fuzz/fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const std::vector<linetrack::Segment2> lines = linetrack::app::ParseLinesCsv(text, "fuzz.csv");
    if (lines.empty()) std::abort();
    for (const linetrack::Segment2& line : lines) {
      if (!line.a.allFinite() || !line.b.allFinite()) std::abort();
    }
  } catch (const linetrack::InputError& e) {
    linetrack::ExpectNamesFile(e, "fuzz.csv");
  }
  return 0;
}
