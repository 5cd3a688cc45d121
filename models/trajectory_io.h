// Trajectory files: ground-truth camera poses in TUM format and the odometry-like prior files the
// localiser reads. Readers throw InputError naming "file:line"; writers return the text (the app
// writes it atomically).
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "models/robot_pose.h"

namespace linetrack {

// The whole text of a file; throws InputError naming it ("no such `what` file", "cannot read").
std::string ReadTextFile(const std::string& path, const std::string& what);

// Exactly `count` finite numbers separated by `sep` (' ' means any run of blanks; fields are
// trimmed). Throws InputError naming path:line_no and, on a wrong count, the `layout`.
std::vector<double> ParseNumberFields(const std::string& line, char sep, size_t count,
                                      const std::string& path, int line_no,
                                      const std::string& layout);

// One pose of a trajectory: time (seconds) and the pose of the camera frame (ViSP axes) in the
// world frame, world_from_cam (the inverse of cam_from_world).
struct StampedPose {
  double t = 0.0;
  Eigen::Isometry3d world_from_cam = Eigen::Isometry3d::Identity();
};

// Parses TUM text: one pose a line, "t x y z qx qy qz qw" (camera centre in the world, unit
// quaternion world_from_cam); blank lines and '#' comments are skipped. Times must increase and
// quaternions be unit within 1e-3 (they are renormalised). `path` names the file in errors.
std::vector<StampedPose> ParseTum(const std::string& text, const std::string& path);

// Reads a TUM file from disk (throws InputError naming the file and line).
std::vector<StampedPose> ReadTum(const std::string& path);

// TUM text of `poses` with a '#' header line; 9 decimals, enough to round-trip to 1e-9.
std::string FormatTum(const std::vector<StampedPose>& poses);

// One row of a prior file: time (seconds) and the prior pose (x, y metres; heading, tilt radians
// in memory, degrees in the file; height metres), conventions of docs/conventions.md.
struct PriorRecord {
  double t = 0.0;
  RobotPose pose;
};

// The header line of a prior file.
inline constexpr const char* kPriorCsvHeader = "t,x,y,heading_deg,height,tilt_deg";

// Parses prior CSV text: the header kPriorCsvHeader, then one row of six finite numbers a line;
// blank lines are skipped, times must increase. `path` names the file in errors.
std::vector<PriorRecord> ParsePriors(const std::string& text, const std::string& path);

// Reads a prior CSV file from disk (throws InputError naming the file and line).
std::vector<PriorRecord> ReadPriors(const std::string& path);

// CSV text of `records` with the header line.
std::string FormatPriors(const std::vector<PriorRecord>& records);

}  // namespace linetrack
