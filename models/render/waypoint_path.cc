#include "models/render/waypoint_path.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/trajectory_io.h"

namespace linetrack {
namespace {

constexpr double kMinSpacing = 0.01;     // metres between consecutive waypoints
constexpr double kMaxTurn = 179.0;       // degrees: sharper corners turn back on the path
constexpr double kArcChordShare = 0.25;  // arc samples every quarter of the path's step

std::string Trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

// A dense polyline of the rounded path and the arc length at which it passes each waypoint.
struct DensePath {
  std::vector<Eigen::Vector2d> points;
  std::vector<double> waypoint_s;

  double Length() const {
    double length = 0.0;
    for (size_t i = 0; i + 1 < points.size(); ++i)
      length += (points[i + 1] - points[i]).norm();
    return length;
  }
  void Add(const Eigen::Vector2d& p) {
    if (points.empty() || (p - points.back()).norm() > 1e-9) points.push_back(p);
  }
};

// The rounded corner at waypoint p between the directions u (in) and v (out): the arc from
// p - d u to p + d v, d = r tan(turn / 2) limited to half of each segment.
struct Corner {
  Eigen::Vector2d start, end, centre;
  double radius = 0.0, start_angle = 0.0, sweep = 0.0;  // sweep signed: > 0 turning left

  Eigen::Vector2d At(double fraction) const {
    const double a = start_angle + fraction * sweep;
    return centre + radius * Eigen::Vector2d(std::cos(a), std::sin(a));
  }
};

Corner RoundCorner(const Eigen::Vector2d& prev, const Eigen::Vector2d& p,
                   const Eigen::Vector2d& next, double radius, const std::string& where) {
  const Eigen::Vector2d u = (p - prev).normalized(), v = (next - p).normalized();
  const double cross = u.x() * v.y() - u.y() * v.x();
  const double turn = std::atan2(std::abs(cross), u.dot(v));  // [0, pi]
  if (turn > DegToRad(kMaxTurn)) {
    throw InputError(where + ": the path turns back on itself here; add a waypoint beside it");
  }
  Corner c;
  c.start = c.end = c.centre = p;
  if (turn < 1e-9) return c;
  const double half_tan = std::tan(0.5 * turn);
  const double d = std::min({radius * half_tan, 0.5 * (p - prev).norm(), 0.5 * (next - p).norm()});
  c.radius = d / half_tan;
  c.start = p - d * u;
  c.end = p + d * v;
  const double side = cross > 0.0 ? 1.0 : -1.0;  // centre on the left when turning left
  c.centre = c.start + side * c.radius * Eigen::Vector2d(-u.y(), u.x());
  c.start_angle = std::atan2(c.start.y() - c.centre.y(), c.start.x() - c.centre.x());
  c.sweep = side * turn;
  return c;
}

// Adds the part [from, to] (fractions) of a corner's arc, sampled every `chord` metres.
void AddArc(const Corner& c, double from, double to, double chord, DensePath* out) {
  const double length = std::abs(c.sweep) * c.radius * (to - from);
  const int n = std::max(1, static_cast<int>(std::ceil(length / chord)));
  for (int k = 0; k <= n; ++k)
    out->Add(c.At(from + (to - from) * k / n));
}

// Uniform resampling of an open polyline: n + 1 points spanning it, n = round(length / step).
std::vector<Eigen::Vector2d> ResampleOpen(const std::vector<Eigen::Vector2d>& line, double step) {
  std::vector<double> cumulative = {0.0};
  for (size_t i = 0; i + 1 < line.size(); ++i)
    cumulative.push_back(cumulative.back() + (line[i + 1] - line[i]).norm());
  const double length = cumulative.back();
  const int n = std::max(1, static_cast<int>(std::round(length / step)));
  std::vector<Eigen::Vector2d> out;
  size_t seg = 0;
  for (int k = 0; k <= n; ++k) {
    const double s = length * k / n;
    while (seg + 2 < line.size() && cumulative[seg + 1] < s)
      ++seg;
    const double span = cumulative[seg + 1] - cumulative[seg];
    const double f = span > 0.0 ? std::clamp((s - cumulative[seg]) / span, 0.0, 1.0) : 0.0;
    out.push_back(line[seg] + f * (line[seg + 1] - line[seg]));
  }
  return out;
}

// The dense rounded path. A closed path starts and ends in the middle of its first corner.
DensePath RoundedPath(const std::vector<Waypoint>& w, bool closed,
                      const WaypointPathOptions& options, const std::string& source) {
  const size_t m = w.size();
  const double chord = kArcChordShare * options.step;
  std::vector<Corner> corners(m);
  for (size_t i = 0; i < m; ++i) {
    const bool end = !closed && (i == 0 || i + 1 == m);
    const Eigen::Vector2d& p = w[i].position;
    if (end) {
      corners[i].start = corners[i].end = corners[i].centre = p;
      continue;
    }
    corners[i] = RoundCorner(w[(i + m - 1) % m].position, p, w[(i + 1) % m].position,
                             options.corner_radius, source + ": waypoint " + std::to_string(i + 1));
  }
  DensePath out;
  for (size_t i = 0; i < m; ++i) {
    const Corner& c = corners[i];
    if (i == 0 && closed) {
      if (c.radius > 0.0) AddArc(c, 0.5, 1.0, chord, &out);
      out.waypoint_s.assign(1, 0.0);
      if (c.radius == 0.0) out.Add(c.start);
      continue;
    }
    if (c.radius > 0.0) {
      AddArc(c, 0.0, 0.5, chord, &out);
      out.waypoint_s.push_back(out.Length());
      AddArc(c, 0.5, 1.0, chord, &out);
    } else {
      out.Add(c.start);
      out.waypoint_s.push_back(out.Length());
    }
  }
  if (closed && corners[0].radius > 0.0) AddArc(corners[0], 0.0, 0.5, chord, &out);
  if (closed && corners[0].radius == 0.0) out.Add(corners[0].start);
  return out;
}

}  // namespace

std::vector<Waypoint> ParseWaypoints(const std::string& text, const std::string& source) {
  std::vector<Waypoint> out;
  std::istringstream in(text);
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::string content = Trim(line.substr(0, line.find('#')));
    if (content.empty()) continue;
    const size_t fields = 1 + std::count(content.begin(), content.end(), ',');
    const std::vector<double> v =
        ParseNumberFields(content, ',', fields == 3 ? 3 : 2, source, number, "x,y[,heading_deg]");
    Waypoint w;
    w.position = {v[0], v[1]};
    if (v.size() == 3) w.heading = DegToRad(v[2]);
    if (!out.empty() && (w.position - out.back().position).norm() < kMinSpacing) {
      throw InputError(
          Located(source, number, "the waypoint repeats the previous one (closer than 1 cm)"));
    }
    out.push_back(w);
  }
  if (out.size() < 2) throw InputError(source + ": a path needs at least two waypoints");
  return out;
}

std::vector<Waypoint> ReadWaypoints(const std::string& path) {
  return ParseWaypoints(ReadTextFile(path, "waypoint"), path);
}

bool WaypointPathOptions::Check(std::string* why) const {
  if (!(corner_radius >= 0.0 && corner_radius <= 100.0) || !(step >= 0.005 && step <= 1.0)) {
    *why = "corner radius must be in [0, 100] metres and step in [0.005, 1] metres";
    return false;
  }
  return true;
}

SampledPath PathThroughWaypoints(const std::vector<Waypoint>& waypoints,
                                 const WaypointPathOptions& options, const std::string& source) {
  std::string why;
  if (!options.Check(&why)) throw InputError(source + ": path: " + why);
  if (waypoints.size() < 2) throw InputError(source + ": a path needs at least two waypoints");
  std::vector<Waypoint> w = waypoints;
  const bool closed =
      w.size() >= 4 && (w.back().position - w.front().position).norm() < kMinSpacing;
  if (closed) {
    if (!w.front().heading) w.front().heading = w.back().heading;
    w.pop_back();
  }
  const DensePath dense = RoundedPath(w, closed, options, source);
  const double dense_length =
      dense.Length() + (closed ? (dense.points.front() - dense.points.back()).norm() : 0.0);
  std::vector<Eigen::Vector2d> points;
  if (closed) {
    const int n = std::max(3, static_cast<int>(std::round(dense_length / options.step)));
    std::vector<Eigen::Vector2d> ring = dense.points;
    ring.push_back(dense.points.front());
    points = ResampleOpen(ring, dense_length / n);
    points.pop_back();  // the first point, again
  } else {
    points = ResampleOpen(dense.points, options.step);
  }
  SampledPath path = SampledPath::Through(std::move(points), closed);
  const bool any_heading =
      std::any_of(w.begin(), w.end(), [](const Waypoint& p) { return p.heading.has_value(); });
  if (!any_heading) return path;

  // Offsets at the waypoints, then linear in arc length between them (the shorter way),
  // accumulated so that they stay continuous along the path.
  const double scale = path.Length() / dense_length;  // resampling keeps the length
  double previous = 0.0;
  for (size_t i = 0; i < w.size(); ++i) {
    const double s = dense.waypoint_s[i] * scale;
    const double offset = w[i].heading ? WrapAngle(*w[i].heading - path.DirectionAt(s)) : 0.0;
    const double continuous = i == 0 ? offset : previous + WrapAngle(offset - previous);
    path.heading_knots.push_back({s, continuous});
    previous = continuous;
  }
  if (closed) {
    const double first = path.heading_knots.front().offset;
    path.heading_knots.push_back({path.Length(), previous + WrapAngle(first - previous)});
  }
  return path;
}

void CheckPathInsideArea(const SampledPath& path, const NavigableArea& area,
                         const std::string& source) {
  for (const Eigen::Vector2d& p : path.points) {
    if (!area.Contains(p)) {
      char text[160];
      std::snprintf(text, sizeof(text),
                    ": the path leaves the navigable area (walls kept %.2f m away) near (%.2f, "
                    "%.2f)",
                    area.clearance(), p.x(), p.y());
      throw InputError(source + text + " [" + area.source() + "]");
    }
  }
}

}  // namespace linetrack
