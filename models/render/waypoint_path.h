// Paths through waypoints for rendered drives: a text file of `x,y[,heading_deg]` lines, the
// polyline through them with its corners rounded, and the base heading along it (the path's
// direction, or the waypoint's heading where one is given).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "models/navigable_area.h"
#include "models/render/sequence.h"

namespace linetrack {

// One waypoint: floor position (metres, world frame) and optionally the base heading there
// (radians, counter-clockwise from +x).
struct Waypoint {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  std::optional<double> heading;
};

// Parses waypoint text: one `x,y` or `x,y,heading_deg` line per waypoint; blank lines and '#'
// comments are skipped. At least two waypoints, consecutive ones apart by 1 cm or more. Throws
// InputError naming `source`:line.
std::vector<Waypoint> ParseWaypoints(const std::string& text, const std::string& source);

// Reads a waypoint file (throws InputError naming the file and line).
std::vector<Waypoint> ReadWaypoints(const std::string& path);

struct WaypointPathOptions {
  double corner_radius = 0.5;  // metres: corners are rounded by arcs of this radius (or less,
                               // when the segments beside a corner are short)
  double step = 0.05;          // metres between the path's samples

  bool Check(std::string* why) const;
};

// The path through `waypoints`: straight segments joined by circular arcs (tangent lengths at
// most half of each segment), sampled every `step` metres. It is closed when the last waypoint
// repeats the first (within 1 cm). The heading offset is 0 at waypoints without a heading and
// heading - direction at the others (the direction at a rounded corner is the arc's middle),
// linear in arc length in between (the shorter way). `source` names the waypoints in errors.
SampledPath PathThroughWaypoints(const std::vector<Waypoint>& waypoints,
                                 const WaypointPathOptions& options, const std::string& source);

// Throws InputError naming `source` and the place when a sample of `path` lies outside `area`
// (NavigableArea::Contains: inside the boundary, outside holes, clear of walls).
void CheckPathInsideArea(const SampledPath& path, const NavigableArea& area,
                         const std::string& source);

}  // namespace linetrack
