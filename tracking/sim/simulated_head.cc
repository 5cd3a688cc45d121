#include "tracking/sim/simulated_head.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack {

bool SimulatedHeadOptions::Check(std::string* why) const {
  const HeadLimits& l = limits;
  if (!(l.pan_min < l.pan_max) || !(l.tilt_min < l.tilt_max)) {
    *why = "joint limits must have min < max";
    return false;
  }
  if (!(l.max_pan_speed > 0.0) || !(l.max_tilt_speed > 0.0)) {
    *why = "maximum speeds must be > 0";
    return false;
  }
  if (!(max_acceleration > 0.0)) {
    *why = "maximum acceleration must be > 0";
    return false;
  }
  if (!(latency_s >= 0.0 && latency_s <= 10.0)) {
    *why = "latency must be in [0, 10] seconds";
    return false;
  }
  if (!(move_speed_fraction > 0.0 && move_speed_fraction <= 1.0)) {
    *why = "move speed fraction must be in (0, 1]";
    return false;
  }
  if (!l.Contains(initial_pan, initial_tilt)) {
    *why = "initial pan and tilt must be within the joint limits";
    return false;
  }
  if (!(max_step_s > 0.0 && max_step_s <= 0.1)) {
    *why = "integration step must be in (0, 0.1] seconds";
    return false;
  }
  return true;
}

void AxisStep(double desired_rate, double max_acceleration, double min, double max, double dt,
              AxisMotion* axis) {
  const double dv =
      std::clamp(desired_rate - axis->rate, -max_acceleration * dt, max_acceleration * dt);
  axis->rate += dv;
  axis->position += axis->rate * dt;
  axis->at_limit = false;
  if (axis->position >= max) {
    axis->position = max;
    axis->rate = std::min(axis->rate, 0.0);
    axis->at_limit = true;
  } else if (axis->position <= min) {
    axis->position = min;
    axis->rate = std::max(axis->rate, 0.0);
    axis->at_limit = true;
  }
}

double RateTowards(double target, double position, double speed, double max_acceleration) {
  const double error = target - position;
  return std::copysign(std::min(speed, std::sqrt(2.0 * max_acceleration * std::abs(error))), error);
}

SimulatedHead::SimulatedHead(const SimulatedHeadOptions& options) : options_(options) {
  std::string why;
  if (!options_.Check(&why)) throw InputError("simulated head: " + why);
  pan_.position = options_.initial_pan;
  tilt_.position = options_.initial_tilt;
  active_ = {0.0, HeadMode::kPosition, options_.initial_pan, options_.initial_tilt};
}

std::string SimulatedHead::Describe() const {
  const HeadLimits& l = options_.limits;
  std::ostringstream out;
  out.precision(4);
  out << "sim (pan " << RadToDeg(l.pan_min) << ".." << RadToDeg(l.pan_max) << " deg, tilt "
      << RadToDeg(l.tilt_min) << ".." << RadToDeg(l.tilt_max) << " deg, "
      << RadToDeg(l.max_pan_speed) << "/" << RadToDeg(l.max_tilt_speed) << " deg/s, "
      << options_.latency_s * 1000.0 << " ms latency)";
  return out.str();
}

HeadLimits SimulatedHead::Limits() const {
  return options_.limits;
}

HeadResult SimulatedHead::Read(HeadState* state) {
  std::lock_guard<std::mutex> lock(mutex_);
  state->time_s = time_;
  state->pan = pan_.position;
  state->tilt = tilt_.position;
  state->pan_rate = pan_.rate;
  state->tilt_rate = tilt_.rate;
  state->mode = active_.mode;
  state->pan_at_limit = pan_.at_limit;
  state->tilt_at_limit = tilt_.at_limit;
  const HeadLimits& l = options_.limits;
  // An axis moves when it has a rate, or is about to: a position target not reached yet, or a
  // velocity command that its joint limit does not block.
  auto axis_moving = [&](const AxisMotion& axis, double command, double min, double max) {
    if (axis.rate != 0.0) return true;
    if (active_.mode == HeadMode::kPosition) return axis.position != command;
    return (command > 0.0 && axis.position < max) || (command < 0.0 && axis.position > min);
  };
  state->moving = !pending_.empty() || axis_moving(pan_, active_.pan, l.pan_min, l.pan_max) ||
                  axis_moving(tilt_, active_.tilt, l.tilt_min, l.tilt_max);
  return HeadResult::Ok();
}

void SimulatedHead::Queue(const Command& command) {
  std::lock_guard<std::mutex> lock(mutex_);
  Command c = command;
  c.apply_time = time_ + options_.latency_s;
  pending_.push_back(c);
}

HeadResult SimulatedHead::MoveTo(double pan, double tilt) {
  if (!options_.limits.Contains(pan, tilt)) {
    std::ostringstream out;
    out << "target pan " << RadToDeg(pan) << ", tilt " << RadToDeg(tilt)
        << " deg outside the joint limits";
    return HeadResult::Error(HeadStatus::kRejected, out.str());
  }
  Queue({0.0, HeadMode::kPosition, pan, tilt});
  return HeadResult::Ok();
}

HeadResult SimulatedHead::SetVelocity(double pan_rate, double tilt_rate) {
  if (!std::isfinite(pan_rate) || !std::isfinite(tilt_rate)) {
    return HeadResult::Error(HeadStatus::kRejected, "velocity is not finite");
  }
  const HeadLimits& l = options_.limits;
  Queue({0.0, HeadMode::kVelocity, std::clamp(pan_rate, -l.max_pan_speed, l.max_pan_speed),
         std::clamp(tilt_rate, -l.max_tilt_speed, l.max_tilt_speed)});
  return HeadResult::Ok();
}

HeadResult SimulatedHead::Stop() {
  Queue({0.0, HeadMode::kVelocity, 0.0, 0.0});
  return HeadResult::Ok();
}

void SimulatedHead::Step(double dt) {
  std::lock_guard<std::mutex> lock(mutex_);
  const HeadLimits& l = options_.limits;
  const double a = options_.max_acceleration;
  double left = dt;
  while (left > 0.0) {
    const double h = std::min(left, options_.max_step_s);
    while (!pending_.empty() && pending_.front().apply_time <= time_ + 1e-12) {
      active_ = pending_.front();
      pending_.pop_front();
    }
    if (active_.mode == HeadMode::kVelocity) {
      AxisStep(active_.pan, a, l.pan_min, l.pan_max, h, &pan_);
      AxisStep(active_.tilt, a, l.tilt_min, l.tilt_max, h, &tilt_);
    } else {
      struct {
        AxisMotion* axis;
        double target, speed, min, max;
      } joints[] = {{&pan_, active_.pan, options_.move_speed_fraction * l.max_pan_speed, l.pan_min,
                     l.pan_max},
                    {&tilt_, active_.tilt, options_.move_speed_fraction * l.max_tilt_speed,
                     l.tilt_min, l.tilt_max}};
      for (auto& j : joints) {
        const double before = j.target - j.axis->position;
        const double rate_before = j.axis->rate;
        AxisStep(RateTowards(j.target, j.axis->position, j.speed, a), a, j.min, j.max, h, j.axis);
        const double after = j.target - j.axis->position;
        // Arrived at the end of the deceleration ramp (the discrete ramp ends near 2 a h):
        // settle on the target. A fast crossing is an overshoot and comes back by itself.
        if ((before == 0.0 && rate_before == 0.0) ||
            (before * after <= 0.0 && std::abs(rate_before) <= 4.0 * a * h)) {
          j.axis->position = j.target;
          j.axis->rate = 0.0;
        }
      }
    }
    time_ += h;
    left -= h;
  }
}

double SimulatedHead::time() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return time_;
}

}  // namespace linetrack
