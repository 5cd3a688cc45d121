#include "app/lines_csv.h"

#include <cmath>
#include <sstream>

#include "models/errors.h"
#include "models/trajectory_io.h"

namespace linetrack::app {
namespace {

constexpr char kLayout[] = "u1,v1,u2,v2";

// True when every comma-separated field of `row` is one finite number (blanks around it allowed).
bool AllNumbers(const std::string& row) {
  std::stringstream fields(row);
  for (std::string field; std::getline(fields, field, ',');) {
    const size_t first = field.find_first_not_of(" \t");
    if (first == std::string::npos) return false;
    try {
      size_t used = 0;
      const double value = std::stod(field.substr(first), &used);
      if (field.find_first_not_of(" \t", first + used) != std::string::npos) return false;
      if (!std::isfinite(value)) return false;
    } catch (const std::exception&) {
      return false;
    }
  }
  return true;
}

}  // namespace

std::vector<Segment2> ParseLinesCsv(const std::string& text, const std::string& path) {
  std::vector<Segment2> lines;
  std::istringstream in(text);
  int number = 0;
  for (std::string row; std::getline(in, row);) {
    ++number;
    if (!row.empty() && row.back() == '\r') row.pop_back();
    if (row.find_first_not_of(" \t") == std::string::npos || row[0] == '#') continue;
    if (number == 1 && !AllNumbers(row)) continue;  // header row
    const std::vector<double> v = ParseNumberFields(row, ',', 4, path, number, kLayout);
    lines.push_back({{v[0], v[1]}, {v[2], v[3]}});
  }
  if (lines.empty()) throw InputError(Located(path, 0, "no line segments"));
  return lines;
}

std::vector<Segment2> ReadLinesCsv(const std::string& path) {
  return ParseLinesCsv(ReadTextFile(path, "lines"), path);
}

}  // namespace linetrack::app
