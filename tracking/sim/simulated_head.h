// A simulated pan-tilt head for `--head sim` and closed-loop tests: joint limits, maximum speed
// and acceleration (trapezoidal profiles), and a command latency, integrated on an explicit
// clock (Step), so that a simulation run is deterministic.
#pragma once

#include <deque>
#include <mutex>
#include <string>

#include "tracking/head/pan_tilt_head.h"

namespace linetrack {

struct SimulatedHeadOptions {
  // Roughly a PTU-D46: pan +-159 deg, tilt from 31 deg up to 47 deg down, 2 rad/s.
  HeadLimits limits = {-2.7751, 2.7751, -0.5411, 0.8203, 2.0, 2.0};
  double max_acceleration = 6.0;                 // rad/s^2, both axes
  double latency_s = 0.02;                       // a command acts this long after it is given
  double move_speed_fraction = 0.5;              // MoveTo speed, as a fraction of the maximum speed
  double initial_pan = 0.0, initial_tilt = 0.0;  // radians
  double max_step_s = 0.001;                     // Step() integrates in sub-steps of at most this

  bool Check(std::string* why) const;
};

// One joint: angle and rate. Pure state for AxisStep.
struct AxisMotion {
  double position = 0.0;  // rad
  double rate = 0.0;      // rad/s
  bool at_limit = false;
};

// Advances one joint by dt toward `desired_rate` with |acceleration| <= max_acceleration, then
// keeps it within [min, max] (stopping it there and flagging at_limit).
void AxisStep(double desired_rate, double max_acceleration, double min, double max, double dt,
              AxisMotion* axis);

// The rate that brings a joint to `target` fastest under `speed` and `max_acceleration` while
// able to stop there: sign(e) min(speed, sqrt(2 a |e|)), e = target - position.
double RateTowards(double target, double position, double speed, double max_acceleration);

class SimulatedHead : public PanTiltHead {
 public:
  // Throws InputError when the options are invalid.
  explicit SimulatedHead(const SimulatedHeadOptions& options = {});

  std::string Describe() const override;
  HeadLimits Limits() const override;
  HeadResult Read(HeadState* state) override;
  HeadResult MoveTo(double pan, double tilt) override;
  HeadResult SetVelocity(double pan_rate, double tilt_rate) override;
  HeadResult Stop() override;

  // Advances the head's clock by dt seconds (commands whose latency has passed take effect).
  void Step(double dt);
  double time() const;

 private:
  struct Command {
    double apply_time = 0.0;
    HeadMode mode = HeadMode::kPosition;
    double pan = 0.0, tilt = 0.0;  // targets (position) or rates (velocity)
  };
  void Queue(const Command& command);

  SimulatedHeadOptions options_;
  mutable std::mutex mutex_;
  double time_ = 0.0;
  AxisMotion pan_, tilt_;
  Command active_;  // what the joints follow now
  std::deque<Command> pending_;
};

}  // namespace linetrack
