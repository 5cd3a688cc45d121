#include "tracking/head/ptu_driver.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "models/errors.h"
#include "models/geometry.h"
#include "tracking/head/ptu_protocol.h"

namespace linetrack {
namespace {

using Clock = SerialLine::Clock;

Clock::duration Seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

std::string Deg(double radians) {
  std::ostringstream out;
  out.precision(4);
  out << RadToDeg(radians);
  return out.str();
}

// Joint range in radians from a count range, whatever the sign.
void CountRange(long lo, long hi, double arcsec, int sign, double* min, double* max) {
  const double a = PtuCountsToRadians(static_cast<double>(lo), arcsec, sign);
  const double b = PtuCountsToRadians(static_cast<double>(hi), arcsec, sign);
  *min = std::min(a, b);
  *max = std::max(a, b);
}

}  // namespace

const char* ToString(HeadStatus status) {
  switch (status) {
    case HeadStatus::kOk:
      return "ok";
    case HeadStatus::kRejected:
      return "rejected";
    case HeadStatus::kTimeout:
      return "timeout";
    case HeadStatus::kIoError:
      return "I/O error";
  }
  return "unknown";
}

bool PtuOptions::Check(std::string* why) const {
  if (device.empty()) {
    *why = "the serial device is empty";
    return false;
  }
  if (!(reply_timeout_s > 0.0 && reply_timeout_s <= 30.0)) {
    *why = "reply timeout must be in (0, 30] seconds";
    return false;
  }
  if ((pan_sign != 1 && pan_sign != -1) || (tilt_sign != 1 && tilt_sign != -1)) {
    *why = "pan and tilt signs must be +1 or -1";
    return false;
  }
  if (!(move_speed_fraction > 0.0 && move_speed_fraction <= 1.0)) {
    *why = "move speed fraction must be in (0, 1]";
    return false;
  }
  return true;
}

std::unique_ptr<PtuDriver> PtuDriver::Open(const PtuOptions& options, HeadResult* result) {
  std::string why;
  if (!options.Check(&why)) throw InputError("ptu:" + options.device + ": " + why);
  std::unique_ptr<PtuDriver> driver(new PtuDriver(options));
  if (!driver->line_.Open(options.device, options.baud, &why)) {
    *result = HeadResult::Error(HeadStatus::kIoError, why);
    return nullptr;
  }
  std::lock_guard<std::mutex> lock(driver->mutex_);
  *result = driver->Initialise();
  if (!result->ok()) return nullptr;
  return driver;
}

PtuDriver::~PtuDriver() = default;

HeadResult PtuDriver::Initialise() {
  std::vector<std::string> replies;
  // Echo off first (its own reply may still carry the echo), then terse replies, independent
  // position control and immediate execution.
  HeadResult r = Transact({"ED"}, &replies);
  if (r.ok()) r = Transact({"FT", "CI", "I"}, &replies);
  if (!r.ok()) {
    if (r.status == HeadStatus::kTimeout) {
      r.message +=
          " (is the unit powered, on this port, at " + std::to_string(options_.baud) + " baud?)";
    }
    return r;
  }
  const std::vector<std::string> queries = {"PR", "TR", "PN", "PX", "TN", "TX", "PU", "TU"};
  r = Transact(queries, &replies);
  if (!r.ok()) return r;
  double v[8];
  for (std::size_t i = 0; i < queries.size(); ++i) {
    if (!ParsePtuNumber(replies[i], &v[i])) {
      return HeadResult::Error(HeadStatus::kRejected,
                               "unreadable reply '" + replies[i] + "' to " + queries[i]);
    }
  }
  unit_.pan_resolution_arcsec = v[0];
  unit_.tilt_resolution_arcsec = v[1];
  unit_.pan_min = std::lround(v[2]);
  unit_.pan_max = std::lround(v[3]);
  unit_.tilt_min = std::lround(v[4]);
  unit_.tilt_max = std::lround(v[5]);
  unit_.pan_max_speed = std::lround(v[6]);
  unit_.tilt_max_speed = std::lround(v[7]);
  if (!(v[0] > 0.0 && v[1] > 0.0) || unit_.pan_min >= unit_.pan_max ||
      unit_.tilt_min >= unit_.tilt_max || unit_.pan_max_speed <= 0 || unit_.tilt_max_speed <= 0) {
    return HeadResult::Error(HeadStatus::kRejected, "the unit reports inconsistent limits");
  }
  CountRange(unit_.pan_min, unit_.pan_max, v[0], options_.pan_sign, &limits_.pan_min,
             &limits_.pan_max);
  CountRange(unit_.tilt_min, unit_.tilt_max, v[1], options_.tilt_sign, &limits_.tilt_min,
             &limits_.tilt_max);
  limits_.max_pan_speed = PtuCountsToRadians(unit_.pan_max_speed, v[0], 1);
  limits_.max_tilt_speed = PtuCountsToRadians(unit_.tilt_max_speed, v[1], 1);

  const long pan_speed =
      std::max(1L, std::lround(options_.move_speed_fraction * unit_.pan_max_speed));
  const long tilt_speed =
      std::max(1L, std::lround(options_.move_speed_fraction * unit_.tilt_max_speed));
  r = Transact({"PS" + std::to_string(pan_speed), "TS" + std::to_string(tilt_speed), "PP", "TP"},
               &replies);
  if (!r.ok()) return r;
  if (!ParsePtuNumber(replies[2], &target_pan_counts_) ||
      !ParsePtuNumber(replies[3], &target_tilt_counts_)) {
    return HeadResult::Error(HeadStatus::kRejected, "unreadable position replies");
  }
  mode_ = HeadMode::kPosition;
  return HeadResult::Ok();
}

void PtuDriver::CountEvents(int pan, int tilt) {
  pan_events_ += pan;
  tilt_events_ += tilt;
  if (pan > 0) pan_stopped_by_limit_ = true;
  if (tilt > 0) tilt_stopped_by_limit_ = true;
}

void PtuDriver::DrainLocked() {
  line_.Poll();
  // Complete lines here are events or replies that came after their command timed out.
  while (!line_.pending_lines().empty()) {
    const PtuLine p = ParsePtuLine(line_.pending_lines().front());
    CountEvents(p.pan_limit_events, p.tilt_limit_events);
    line_.pending_lines().pop_front();
  }
  int pan = 0, tilt = 0;
  if (TakePtuEvents(line_.partial(), &pan, &tilt)) {
    CountEvents(pan, tilt);
    line_.partial().clear();
  }
}

HeadResult PtuDriver::Transact(const std::vector<std::string>& commands,
                               std::vector<std::string>* replies) {
  DrainLocked();
  std::string text;
  for (const std::string& c : commands)
    text += c + " ";
  std::string why;
  if (!line_.Write(text, Clock::now() + Seconds(options_.reply_timeout_s), &why)) {
    return HeadResult::Error(HeadStatus::kIoError, why);
  }
  replies->assign(commands.size(), std::string());
  HeadResult result;
  for (std::size_t i = 0; i < commands.size(); ++i) {
    const Clock::time_point deadline = Clock::now() + Seconds(options_.reply_timeout_s);
    for (;;) {
      std::string line;
      const SerialLine::ReadStatus status = line_.ReadLine(deadline, &line, &why);
      if (status == SerialLine::ReadStatus::kTimeout) {
        std::ostringstream out;
        out << "no reply to '" << commands[i] << "' within " << options_.reply_timeout_s
            << " s from " << options_.device;
        return HeadResult::Error(HeadStatus::kTimeout, out.str());
      }
      if (status == SerialLine::ReadStatus::kError) {
        return HeadResult::Error(HeadStatus::kIoError, why);
      }
      const PtuLine p = ParsePtuLine(line);
      CountEvents(p.pan_limit_events, p.tilt_limit_events);
      if (p.kind == PtuLine::Kind::kNone) continue;  // events, echo or noise
      (*replies)[i] = p.text;
      if (p.kind == PtuLine::Kind::kError && result.ok()) {
        result = HeadResult::Error(HeadStatus::kRejected, "'" + commands[i] + "': " + p.text);
      }
      break;
    }
  }
  return result;
}

HeadResult PtuDriver::EnsureMode(HeadMode mode) {
  if (mode_ == mode) return HeadResult::Ok();
  std::vector<std::string> replies;
  HeadResult r;
  if (mode == HeadMode::kVelocity) {
    // Halt first: in pure velocity mode the speed registers become signed velocities.
    r = Transact({"H", "CV", "PS0", "TS0"}, &replies);
    pan_rate_ = tilt_rate_ = 0.0;
  } else {
    const long pan_speed = std::lround(options_.move_speed_fraction * unit_.pan_max_speed);
    const long tilt_speed = std::lround(options_.move_speed_fraction * unit_.tilt_max_speed);
    r = Transact({"H", "CI", "PS" + std::to_string(std::max(1L, pan_speed)),
                  "TS" + std::to_string(std::max(1L, tilt_speed))},
                 &replies);
  }
  if (r.ok()) mode_ = mode;
  return r;
}

HeadResult PtuDriver::Read(HeadState* state) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> replies;
  const HeadResult r = Transact({"PP", "TP"}, &replies);
  if (!r.ok()) return r;
  double pan = 0.0, tilt = 0.0;
  if (!ParsePtuNumber(replies[0], &pan) || !ParsePtuNumber(replies[1], &tilt)) {
    return HeadResult::Error(HeadStatus::kRejected,
                             "unreadable position '" + replies[0] + "', '" + replies[1] + "'");
  }
  state->time_s = std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
  state->pan = PtuCountsToRadians(pan, unit_.pan_resolution_arcsec, options_.pan_sign);
  state->tilt = PtuCountsToRadians(tilt, unit_.tilt_resolution_arcsec, options_.tilt_sign);
  state->mode = mode_;
  state->pan_at_limit = pan_stopped_by_limit_ || pan <= unit_.pan_min || pan >= unit_.pan_max;
  state->tilt_at_limit = tilt_stopped_by_limit_ || tilt <= unit_.tilt_min || tilt >= unit_.tilt_max;
  if (mode_ == HeadMode::kVelocity) {
    state->pan_rate = pan_stopped_by_limit_ ? 0.0 : pan_rate_;
    state->tilt_rate = tilt_stopped_by_limit_ ? 0.0 : tilt_rate_;
    state->moving = state->pan_rate != 0.0 || state->tilt_rate != 0.0;
  } else {
    state->pan_rate = state->tilt_rate = 0.0;  // the unit does not report its speed
    state->moving =
        std::abs(pan - target_pan_counts_) >= 1.0 || std::abs(tilt - target_tilt_counts_) >= 1.0;
  }
  return HeadResult::Ok();
}

HeadResult PtuDriver::MoveTo(double pan, double tilt) {
  if (!limits_.Contains(pan, tilt)) {
    return HeadResult::Error(HeadStatus::kRejected,
                             "target pan " + Deg(pan) + ", tilt " + Deg(tilt) +
                                 " deg outside pan [" + Deg(limits_.pan_min) + ", " +
                                 Deg(limits_.pan_max) + "], tilt [" + Deg(limits_.tilt_min) + ", " +
                                 Deg(limits_.tilt_max) + "] deg");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  HeadResult r = EnsureMode(HeadMode::kPosition);
  if (!r.ok()) return r;
  const long pan_counts = std::clamp(
      std::lround(PtuRadiansToCounts(pan, unit_.pan_resolution_arcsec, options_.pan_sign)),
      unit_.pan_min, unit_.pan_max);
  const long tilt_counts = std::clamp(
      std::lround(PtuRadiansToCounts(tilt, unit_.tilt_resolution_arcsec, options_.tilt_sign)),
      unit_.tilt_min, unit_.tilt_max);
  std::vector<std::string> replies;
  r = Transact({"PP" + std::to_string(pan_counts), "TP" + std::to_string(tilt_counts)}, &replies);
  if (r.ok()) {
    target_pan_counts_ = static_cast<double>(pan_counts);
    target_tilt_counts_ = static_cast<double>(tilt_counts);
    pan_stopped_by_limit_ = tilt_stopped_by_limit_ = false;
  }
  return r;
}

HeadResult PtuDriver::SetVelocity(double pan_rate, double tilt_rate) {
  if (!std::isfinite(pan_rate) || !std::isfinite(tilt_rate)) {
    return HeadResult::Error(HeadStatus::kRejected, "velocity is not finite");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  HeadResult r = EnsureMode(HeadMode::kVelocity);
  if (!r.ok()) return r;
  pan_rate = std::clamp(pan_rate, -limits_.max_pan_speed, limits_.max_pan_speed);
  tilt_rate = std::clamp(tilt_rate, -limits_.max_tilt_speed, limits_.max_tilt_speed);
  const long pan_counts = std::clamp(
      std::lround(PtuRadiansToCounts(pan_rate, unit_.pan_resolution_arcsec, options_.pan_sign)),
      -unit_.pan_max_speed, unit_.pan_max_speed);
  const long tilt_counts = std::clamp(
      std::lround(PtuRadiansToCounts(tilt_rate, unit_.tilt_resolution_arcsec, options_.tilt_sign)),
      -unit_.tilt_max_speed, unit_.tilt_max_speed);
  std::vector<std::string> replies;
  r = Transact({"PS" + std::to_string(pan_counts), "TS" + std::to_string(tilt_counts)}, &replies);
  if (r.ok()) {
    pan_rate_ = PtuCountsToRadians(pan_counts, unit_.pan_resolution_arcsec, options_.pan_sign);
    tilt_rate_ = PtuCountsToRadians(tilt_counts, unit_.tilt_resolution_arcsec, options_.tilt_sign);
    pan_stopped_by_limit_ = tilt_stopped_by_limit_ = false;
  }
  return r;
}

HeadResult PtuDriver::Stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> replies;
  HeadResult r = mode_ == HeadMode::kVelocity ? Transact({"H", "PS0", "TS0"}, &replies)
                                              : Transact({"H", "PP", "TP"}, &replies);
  if (!r.ok()) return r;
  pan_rate_ = tilt_rate_ = 0.0;
  if (mode_ == HeadMode::kPosition) {
    // Halted where it was: that is the new target.
    ParsePtuNumber(replies[1], &target_pan_counts_);
    ParsePtuNumber(replies[2], &target_tilt_counts_);
  }
  return r;
}

std::string PtuDriver::Describe() const {
  std::ostringstream out;
  out << "ptu:" << options_.device << " (pan " << Deg(limits_.pan_min) << ".."
      << Deg(limits_.pan_max) << " deg, tilt " << Deg(limits_.tilt_min) << ".."
      << Deg(limits_.tilt_max) << " deg, " << unit_.pan_resolution_arcsec << "/"
      << unit_.tilt_resolution_arcsec << " arcsec per count)";
  return out.str();
}

HeadLimits PtuDriver::Limits() const {
  return limits_;
}

int PtuDriver::pan_limit_events() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return pan_events_;
}

int PtuDriver::tilt_limit_events() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return tilt_events_;
}

}  // namespace linetrack
