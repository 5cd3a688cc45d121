// Re-localisation of a robot camera with the interpretation-tree matcher: line segments from an
// injected extractor, a prior from the robot (odometry carried from the last good pose, or the
// last good pose itself) and search bounds that widen with the time since the last good pose.
#pragma once

#include <visp3/core/vpImage.h>

#include <optional>
#include <string>
#include <vector>

#include "matching/lines/line_extractor.h"
#include "matching/localizer.h"
#include "models/geometry.h"
#include "models/robot_pose.h"

namespace linetrack {

// Prior position and heading bounds of the matcher (metres, radians).
struct SearchBounds {
  double delta_t = 0.75;
  double delta_phi = 0.3490658503988659;  // 20 degrees: the paper's QI3
};

struct RelocalizationOptions {
  // First localisation, and a prior read from the file as it is.
  SearchBounds initial;
  // A prior carried from the last good pose, at the loss: 0.3 m, 10 degrees.
  SearchBounds after_loss{0.3, 0.17453292519943295};
  double growth_t = 0.05;      // metres added per frame since the last good pose
  double growth_phi = 0.0175;  // radians added per frame (1 degree)
  // The widest bounds: 1.5 m, 45 degrees.
  SearchBounds max{1.5, 0.7853981633974483};
  int min_lines = 4;  // fewer extracted lines: no attempt

  bool Check(std::string* why) const;
};

// Bounds `frames_since_good` frames after the last good pose: after_loss grown linearly, capped
// at max.
SearchBounds WidenedBounds(int frames_since_good, const RelocalizationOptions& options);

// The robot's prior now, carried from the last good pose by the odometry since then: the planar
// motion odometry_now (-) odometry_then expressed in the odometry's frame at `then`, applied to
// `last_good` (SE(2) composition); height, tilt and roll are the current readings.
RobotPose CarryPrior(const RobotPose& last_good, const RobotPose& odometry_then,
                     const RobotPose& odometry_now);

// The segments the matchers accept (finite, at least 1 pixel long): an extractor may produce
// degenerate ones, which the matchers reject as bad input.
std::vector<Segment2> UsableSegments(const std::vector<Segment2>& lines);

// One matcher run.
struct RelocalizationAttempt {
  bool found = false;
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();  // when found
  int lines = 0;                                                     // segments extracted
  double extract_ms = 0.0;
  double match_ms = 0.0;
  std::string reason;  // why nothing was found
};

class Relocalizer {
 public:
  // The localizer must outlive the relocalizer. `extractor` gives the segments of an undistorted
  // grey image in its pixels (injected: matching/lines' LineExtractor, or any other).
  Relocalizer(const Localizer& localizer, LineExtractorFunction extractor,
              const RelocalizationOptions& options = {});

  // Extracts lines from `undistorted` and runs the matcher around `prior` (its height, tilt and
  // roll are taken as known) within `bounds`.
  RelocalizationAttempt Attempt(const vpImage<unsigned char>& undistorted, const RobotPose& prior,
                                const SearchBounds& bounds) const;

  const RelocalizationOptions& options() const { return options_; }

 private:
  const Localizer& localizer_;
  LineExtractorFunction extractor_;
  RelocalizationOptions options_;
};

}  // namespace linetrack
