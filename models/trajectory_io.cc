#include "models/trajectory_io.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack {
namespace {

constexpr double kUnitQuaternionTol = 1e-3;

// Strips a trailing '\r' and surrounding blanks.
std::string Trimmed(std::string line) {
  const size_t first = line.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  const size_t last = line.find_last_not_of(" \t\r");
  return line.substr(first, last - first + 1);
}

void CheckIncreasing(double t, bool first, double previous, const std::string& path, int line_no) {
  if (!first && !(t > previous)) {
    throw InputError(Located(path, line_no, "time does not increase"));
  }
}

std::string Format(const char* pattern, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), pattern, value);
  return buffer;
}

}  // namespace

std::string ReadTextFile(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(Located(path, 0, "no such " + what + " file"));
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw InputError(Located(path, 0, "cannot read the " + what + " file"));
  return text.str();
}

std::vector<double> ParseNumberFields(const std::string& line, char sep, size_t count,
                                      const std::string& path, int line_no,
                                      const std::string& layout) {
  std::vector<std::string> fields;
  if (sep == ' ') {
    std::istringstream in(line);
    std::string field;
    while (in >> field)
      fields.push_back(field);
  } else {
    std::stringstream in(line);
    std::string field;
    while (std::getline(in, field, sep))
      fields.push_back(Trimmed(field));
    if (!line.empty() && line.back() == sep) fields.push_back("");
  }
  if (fields.size() != count) {
    throw InputError(Located(path, line_no,
                             "expected " + std::to_string(count) + " numbers (" + layout +
                                 "), got " + std::to_string(fields.size())));
  }
  std::vector<double> values;
  for (const std::string& field : fields) {
    double value = 0.0;
    try {
      size_t used = 0;
      value = std::stod(field, &used);
      if (used != field.size()) throw std::invalid_argument(field);
    } catch (const std::exception&) {
      throw InputError(Located(path, line_no, "not a number: '" + field + "'"));
    }
    if (!std::isfinite(value)) {
      throw InputError(Located(path, line_no, "not a finite number: '" + field + "'"));
    }
    values.push_back(value);
  }
  return values;
}

std::vector<StampedPose> ParseTum(const std::string& text, const std::string& path) {
  std::vector<StampedPose> poses;
  std::istringstream in(text);
  std::string raw;
  int line_no = 0;
  while (std::getline(in, raw)) {
    ++line_no;
    const std::string line = Trimmed(raw);
    if (line.empty() || line[0] == '#') continue;
    const std::vector<double> v =
        ParseNumberFields(line, ' ', 8, path, line_no, "t x y z qx qy qz qw");
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > kUnitQuaternionTol) {
      throw InputError(Located(path, line_no, "the quaternion is not of unit length"));
    }
    CheckIncreasing(v[0], poses.empty(), poses.empty() ? 0.0 : poses.back().t, path, line_no);
    StampedPose pose;
    pose.t = v[0];
    pose.world_from_cam.linear() = q.normalized().toRotationMatrix();
    pose.world_from_cam.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    poses.push_back(pose);
  }
  if (poses.empty()) throw InputError(Located(path, 0, "no poses in the trajectory file"));
  return poses;
}

std::vector<StampedPose> ReadTum(const std::string& path) {
  return ParseTum(ReadTextFile(path, "trajectory"), path);
}

std::string FormatTum(const std::vector<StampedPose>& poses) {
  std::string out = "# t x y z qx qy qz qw (world_from_cam, ViSP camera axes)\n";
  for (const StampedPose& p : poses) {
    const Eigen::Quaterniond q(p.world_from_cam.linear());
    const Eigen::Vector3d c = p.world_from_cam.translation();
    out += Format("%.6f", p.t);
    for (double value : {c.x(), c.y(), c.z(), q.x(), q.y(), q.z(), q.w()}) {
      out += Format(" %.9f", value);
    }
    out += "\n";
  }
  return out;
}

std::vector<PriorRecord> ParsePriors(const std::string& text, const std::string& path) {
  std::vector<PriorRecord> records;
  std::istringstream in(text);
  std::string raw;
  int line_no = 0;
  bool header_seen = false;
  while (std::getline(in, raw)) {
    ++line_no;
    const std::string line = Trimmed(raw);
    if (line.empty()) continue;
    if (!header_seen) {
      if (line != kPriorCsvHeader) {
        throw InputError(
            Located(path, line_no, std::string("expected the header '") + kPriorCsvHeader + "'"));
      }
      header_seen = true;
      continue;
    }
    const std::vector<double> v = ParseNumberFields(line, ',', 6, path, line_no, kPriorCsvHeader);
    if (v[4] <= 0.0) {
      throw InputError(
          Located(path, line_no, "height: not a camera height (metres above the floor, > 0)"));
    }
    if (std::abs(v[5]) > 90.0)
      throw InputError(Located(path, line_no, "tilt must be in [-90, 90]"));
    CheckIncreasing(v[0], records.empty(), records.empty() ? 0.0 : records.back().t, path, line_no);
    PriorRecord record;
    record.t = v[0];
    record.pose = {v[1], v[2], WrapAngle(DegToRad(v[3])), v[4], DegToRad(v[5])};
    records.push_back(record);
  }
  if (!header_seen) throw InputError(Located(path, 0, "empty prior file"));
  return records;
}

std::vector<PriorRecord> ReadPriors(const std::string& path) {
  return ParsePriors(ReadTextFile(path, "prior"), path);
}

std::string FormatPriors(const std::vector<PriorRecord>& records) {
  std::string out = std::string(kPriorCsvHeader) + "\n";
  for (const PriorRecord& r : records) {
    out += Format("%.6f", r.t) + Format(",%.6f", r.pose.x) + Format(",%.6f", r.pose.y) +
           Format(",%.6f", RadToDeg(WrapAngle(r.pose.heading))) + Format(",%.6f", r.pose.height) +
           Format(",%.6f", RadToDeg(r.pose.tilt)) + "\n";
  }
  return out;
}

}  // namespace linetrack
