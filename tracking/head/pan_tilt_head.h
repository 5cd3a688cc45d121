// One interface for pan-tilt heads: the FLIR/Directed Perception PTU driver, the simulated head.
// Joint angles follow the project's conventions (docs/conventions.md): pan is counter-
// clockwise seen from above (it adds to the robot heading), tilt is positive looking down. Both
// are zero when the camera looks straight ahead, level. Radians, radians per second.
#pragma once

#include <string>

namespace linetrack {

// Joint ranges and speed limits of a head (radians, radians per second).
struct HeadLimits {
  double pan_min = 0.0, pan_max = 0.0;
  double tilt_min = 0.0, tilt_max = 0.0;
  double max_pan_speed = 0.0, max_tilt_speed = 0.0;

  bool Contains(double pan, double tilt) const {
    return pan >= pan_min && pan <= pan_max && tilt >= tilt_min && tilt <= tilt_max;
  }
};

// How the head is being driven: to positions (at the move speed) or at commanded velocities.
enum class HeadMode { kPosition, kVelocity };

// What the head reports.
struct HeadState {
  double time_s = 0.0;  // when the state was read: the head's own clock (simulated) or the host's
  double pan = 0.0, tilt = 0.0;            // radians
  double pan_rate = 0.0, tilt_rate = 0.0;  // rad/s: simulated, or last commanded (PTU)
  HeadMode mode = HeadMode::kPosition;
  bool moving = false;
  bool pan_at_limit = false, tilt_at_limit = false;  // at a joint limit, or stopped by one
};

// Outcome of a head call. Errors are results, never hangs: every exchange has a timeout.
enum class HeadStatus {
  kOk,
  kRejected,  // the head refused the command (out of limits, bad argument): nothing moved
  kTimeout,   // no answer in time
  kIoError,   // the link failed (device missing, write error)
};

const char* ToString(HeadStatus status);  // "ok", "rejected", "timeout", "I/O error"

struct HeadResult {
  HeadStatus status = HeadStatus::kOk;
  std::string message;  // what went wrong, for logs (empty when ok)

  bool ok() const { return status == HeadStatus::kOk; }
  static HeadResult Ok() { return {}; }
  static HeadResult Error(HeadStatus status, std::string message) {
    return {status, std::move(message)};
  }
};

// A pan-tilt head. Implementations are thread-safe unless they say otherwise.
class PanTiltHead {
 public:
  virtual ~PanTiltHead() = default;

  virtual std::string Describe() const = 0;
  virtual HeadLimits Limits() const = 0;

  // Current joint angles and state.
  virtual HeadResult Read(HeadState* state) = 0;

  // Goes to (pan, tilt) at the head's move speed. Rejected, nothing moving, outside the limits.
  virtual HeadResult MoveTo(double pan, double tilt) = 0;

  // Turns at (pan_rate, tilt_rate) rad/s, clamped to the maximum speeds; an axis stops at its
  // limit (and reports it). The servo's command.
  virtual HeadResult SetVelocity(double pan_rate, double tilt_rate) = 0;

  // Halts both axes now.
  virtual HeadResult Stop() = 0;
};

}  // namespace linetrack
