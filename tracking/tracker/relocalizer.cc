#include "tracking/tracker/relocalizer.h"

#include <chrono>
#include <cmath>

#include "models/errors.h"
#include "models/text_format.h"

namespace linetrack {

namespace {

bool ValidBounds(const SearchBounds& b) {
  return b.delta_t >= 0.0 && std::isfinite(b.delta_t) && b.delta_phi > 0.0 && b.delta_phi <= kPi;
}

}  // namespace

bool RelocalizationOptions::Check(std::string* why) const {
  if (!ValidBounds(initial) || !ValidBounds(after_loss) || !ValidBounds(max)) {
    *why = "search bounds must have delta_t >= 0 and delta_phi in (0, 180] degrees";
    return false;
  }
  if (!(growth_t >= 0.0) || !(growth_phi >= 0.0)) {
    *why = "bound growth must be >= 0";
    return false;
  }
  if (min_lines < 2) {
    *why = "min_lines must be >= 2";
    return false;
  }
  return true;
}

SearchBounds WidenedBounds(int frames_since_good, const RelocalizationOptions& options) {
  const double frames = std::max(0, frames_since_good);
  SearchBounds bounds;
  bounds.delta_t =
      std::min(options.max.delta_t, options.after_loss.delta_t + options.growth_t * frames);
  bounds.delta_phi =
      std::min(options.max.delta_phi, options.after_loss.delta_phi + options.growth_phi * frames);
  return bounds;
}

RobotPose CarryPrior(const RobotPose& last_good, const RobotPose& odometry_then,
                     const RobotPose& odometry_now) {
  // Motion in the odometry frame at `then`: d = R(-h_then) (p_now - p_then).
  const double c = std::cos(odometry_then.heading), s = std::sin(odometry_then.heading);
  const double dx = odometry_now.x - odometry_then.x, dy = odometry_now.y - odometry_then.y;
  const double forward = c * dx + s * dy, left = -s * dx + c * dy;
  const double cg = std::cos(last_good.heading), sg = std::sin(last_good.heading);
  RobotPose prior;
  prior.x = last_good.x + cg * forward - sg * left;
  prior.y = last_good.y + sg * forward + cg * left;
  prior.heading = WrapAngle(last_good.heading + (odometry_now.heading - odometry_then.heading));
  prior.height = odometry_now.height;
  prior.tilt = odometry_now.tilt;
  prior.roll = odometry_now.roll;
  return prior;
}

std::vector<Segment2> UsableSegments(const std::vector<Segment2>& lines) {
  std::vector<Segment2> usable;
  for (const Segment2& line : lines) {
    if (line.a.allFinite() && line.b.allFinite() && line.Length() >= 1.0) usable.push_back(line);
  }
  return usable;
}

Relocalizer::Relocalizer(const Localizer& localizer, LineExtractorFunction extractor,
                         const RelocalizationOptions& options)
    : localizer_(localizer), extractor_(std::move(extractor)), options_(options) {
  std::string why;
  if (!extractor_) throw InputError("relocalizer: no line extractor");
  if (!options_.Check(&why)) throw InputError("relocalization options: " + why);
}

RelocalizationAttempt Relocalizer::Attempt(const vpImage<unsigned char>& undistorted,
                                           const RobotPose& prior,
                                           const SearchBounds& bounds) const {
  RelocalizationAttempt attempt;
  auto start = std::chrono::steady_clock::now();
  LocalizationProblem problem;
  problem.lines = UsableSegments(extractor_(undistorted));
  attempt.extract_ms = MillisecondsSince(start);
  attempt.lines = static_cast<int>(problem.lines.size());
  if (attempt.lines < options_.min_lines) {
    attempt.reason = std::to_string(attempt.lines) + " lines extracted";
    return attempt;
  }
  problem.prior = prior.Planar();
  problem.delta_t = bounds.delta_t;
  problem.delta_phi = bounds.delta_phi;
  problem.height = prior.height;
  problem.tilt = prior.tilt;
  problem.roll = prior.roll;
  start = std::chrono::steady_clock::now();
  const LocalizationResult result = localizer_.Localize(problem);
  attempt.match_ms = MillisecondsSince(start);
  attempt.found = result.found;
  if (result.found) {
    attempt.cam_from_world = result.cam_from_world;
  } else {
    attempt.reason = "matcher: " + result.reason;
  }
  return attempt;
}

}  // namespace linetrack
