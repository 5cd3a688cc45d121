// Per-frame readings for replay: the robot's prior (odometry and head encoders) at a frame's time,
// interpolated in a prior file, and the ground-truth pose at a frame's time in a TUM trajectory.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "models/trajectory_io.h"

namespace linetrack {

// The prior at time t (seconds): linear interpolation of x, y, height and tilt between the two
// records around t, the heading and roll along the shorter way; outside the records' time range the
// first or last record when within max_gap seconds, else nullopt.
std::optional<RobotPose> InterpolatePrior(const std::vector<PriorRecord>& records, double t,
                                          double max_gap);

// cam_from_world of the pose nearest to t (seconds) when within tolerance seconds, else nullopt.
// `poses` must be sorted by time (ReadTum checks it).
std::optional<Eigen::Isometry3d> GroundTruthAt(const std::vector<StampedPose>& poses, double t,
                                               double tolerance);

// Median of the differences of consecutive times (seconds); 0 for fewer than two times.
double MedianTimeStep(const std::vector<double>& times);

}  // namespace linetrack
