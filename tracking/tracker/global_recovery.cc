#include "tracking/tracker/global_recovery.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "models/errors.h"
#include "models/text_format.h"
#include "tracking/tracker/relocalizer.h"

namespace linetrack {

bool GlobalRecoveryOptions::Check(std::string* why) const {
  if (!(kidnap_s >= 0.0) || !(lost_s >= 0.0) || kidnap_min_lines < 0 || kidnap_min_frames < 1) {
    *why =
        "global mode: the seconds before the switch and the lines must be >= 0 (0: off), the "
        "frames of a carry >= 1";
    return false;
  }
  if (!(rival_distance_m > 0.0) || !(rival_heading_deg > 0.0)) {
    *why = "global mode: the rival distance and heading must be > 0";
    return false;
  }
  if (!(lost_distance_m >= 0.0)) {
    *why = "global mode: the distance must be >= 0 metres (0: off)";
    return false;
  }
  return true;
}

int FramesIn(double seconds, double period_s) {
  if (!(seconds > 0.0) || !(period_s > 0.0)) return 0;
  // A relative tolerance so that 0.3 s at 0.1 s (0.30000000000000004 / 0.1) gives 3 frames.
  return std::max(1, static_cast<int>(std::ceil(seconds / period_s - 1e-6)));
}

int CarryFrames(const GlobalRecoveryOptions& options, double period_s) {
  const int frames = FramesIn(options.kidnap_s, period_s);
  return frames > 0 ? std::max(frames, options.kidnap_min_frames) : 0;
}

bool ShowsElsewhere(const GlobalAttempt& attempt, const Pose3Dof& prior,
                    const GlobalRecoveryOptions& options) {
  const auto away = [&](const Pose3Dof& pose) {
    const double heading = std::abs(std::remainder(pose.heading - prior.heading, 2.0 * kPi));
    return std::hypot(pose.x - prior.x, pose.y - prior.y) > options.rival_distance_m ||
           heading > DegToRad(options.rival_heading_deg);
  };
  if (attempt.found) return away(attempt.planar);
  if (!attempt.ambiguous) return false;
  // An ambiguous view refutes the prior only when none of its rivals lies near it.
  return std::all_of(attempt.rival_poses.begin(), attempt.rival_poses.end(), away);
}

std::string GlobalModeReason(const LossState& s, const GlobalRecoveryOptions& o) {
  if (!s.has_prior) return "no prior";
  const bool odometry = s.driven_since_m >= 0.0;
  const int kidnap_frames = CarryFrames(o, s.frame_period_s);
  if (kidnap_frames > 0 && s.carry_frames >= kidnap_frames) {
    return "carried away: " + std::to_string(s.carry_frames) +
           " frames show the robot away from the carried prior";
  }
  const int lost_frames = FramesIn(o.lost_s, s.frame_period_s);
  if (lost_frames > 0 && s.frames_since_good >= lost_frames) {
    return "lost " + std::to_string(s.frames_since_good) + " frames (" +
           Fixed(s.frames_since_good * s.frame_period_s, 1) + " s)";
  }
  if (o.lost_distance_m > 0.0 && odometry && s.driven_since_m >= o.lost_distance_m) {
    return "lost over " + Fixed(s.driven_since_m, 1) + " m";
  }
  return "";
}

GlobalRecovery::GlobalRecovery(const GlobalLocalizer& global, LineExtractorFunction extractor,
                               int min_lines)
    : global_(global), extractor_(std::move(extractor)), min_lines_(min_lines) {
  if (!extractor_) throw InputError("global recovery: no line extractor");
}

GlobalAttempt GlobalRecovery::Attempt(const vpImage<unsigned char>& undistorted, double height,
                                      double tilt) const {
  const auto start = std::chrono::steady_clock::now();
  GlobalAttempt attempt;
  GlobalProblem problem;
  problem.lines = UsableSegments(extractor_(undistorted));
  problem.height = height;
  problem.tilt = tilt;
  attempt.lines = static_cast<int>(problem.lines.size());
  if (attempt.lines < min_lines_) {
    attempt.reason = "global: " + std::to_string(attempt.lines) + " lines extracted";
    attempt.ms = MillisecondsSince(start);
    return attempt;
  }
  const GlobalResult result = global_.Localize(problem);
  attempt.ms = MillisecondsSince(start);
  attempt.ambiguous = result.ambiguous;
  attempt.rivals = static_cast<int>(result.rivals.size());
  attempt.rival_poses = result.rivals;
  if (result.found && !result.ambiguous) {
    attempt.found = true;
    attempt.cam_from_world = result.best.cam_from_world;
    attempt.planar = RobotPoseFromCamFromWorld(attempt.cam_from_world).Planar();
  } else {
    attempt.reason = "global: " + result.reason;
  }
  return attempt;
}

}  // namespace linetrack
