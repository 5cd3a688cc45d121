#include "models/render/frame_truth.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "models/errors.h"
#include "models/trajectory_io.h"

namespace linetrack {
namespace {

constexpr size_t kFields = 12;

std::string Row(const FrameTruth& r) {
  char text[320];
  std::snprintf(text, sizeof(text), "%ld,%.6f,%d,%d,%d,%.4f,%d,%.2f,%.5f,%.5f,%.3f,%.3f\n", r.frame,
                r.t, r.observable ? 1 : 0, r.observable_edges, r.covered ? 1 : 0, r.gain,
                r.shutter_samples, r.blur_px, r.people_share, r.clutter_share, r.centre_depth_m,
                r.pan_deg);
  return text;
}

}  // namespace

std::string FormatFrameTruth(const std::vector<FrameTruth>& rows) {
  std::string out = std::string(kFrameTruthHeader) + "\n";
  for (const FrameTruth& r : rows)
    out += Row(r);
  return out;
}

std::vector<FrameTruth> ParseFrameTruth(const std::string& text, const std::string& source) {
  std::vector<FrameTruth> rows;
  std::istringstream in(text);
  std::string line;
  int number = 0;
  bool header = false;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (!header) {
      if (line != kFrameTruthHeader) {
        throw InputError(Located(source, number,
                                 std::string("expected the header '") + kFrameTruthHeader + "'"));
      }
      header = true;
      continue;
    }
    const std::vector<double> v =
        ParseNumberFields(line, ',', kFields, source, number, kFrameTruthHeader);
    FrameTruth r;
    r.frame = std::lround(v[0]);
    if (!rows.empty() && r.frame <= rows.back().frame) {
      throw InputError(Located(source, number, "frame numbers must increase"));
    }
    r.t = v[1];
    r.observable = v[2] != 0.0;
    r.observable_edges = static_cast<int>(std::lround(v[3]));
    r.covered = v[4] != 0.0;
    r.gain = v[5];
    r.shutter_samples = static_cast<int>(std::lround(v[6]));
    r.blur_px = v[7];
    r.people_share = v[8];
    r.clutter_share = v[9];
    r.centre_depth_m = v[10];
    r.pan_deg = v[11];
    rows.push_back(r);
  }
  if (!header) throw InputError(Located(source, 0, "empty frame truth file"));
  return rows;
}

std::vector<FrameTruth> ReadFrameTruth(const std::string& path) {
  return ParseFrameTruth(ReadTextFile(path, "frame truth"), path);
}

}  // namespace linetrack
