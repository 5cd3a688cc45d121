// The image line segments of `localize --lines`, `heading` and `views`: a CSV of `u1,v1,u2,v2`
// rows in pixels, as `linetrack lines` writes it. Apart from the rest of localize's files so that
// the lines fuzzer (tests/fuzz/lines_fuzzer.cc) can build it alone.
#pragma once

#include <string>
#include <vector>

#include "models/geometry.h"

namespace linetrack::app {

// Parses `u1,v1,u2,v2` rows (pixels; four finite numbers a row, blanks around them allowed). A
// first line that is not all numbers is a header; blank lines and lines starting with '#' are
// skipped. Throws InputError "path:line: what" naming `path`, or "path: no line segments".
std::vector<Segment2> ParseLinesCsv(const std::string& text, const std::string& path);

// ParseLinesCsv of the file at `path`; throws InputError naming it when it cannot be read.
std::vector<Segment2> ReadLinesCsv(const std::string& path);

}  // namespace linetrack::app
