// Driver of FLIR (Directed Perception) PTU-D46/E46 pan-tilt units over their ASCII serial
// protocol (tracking/head/ptu_protocol.h). Opening switches echo off and terse feedback on,
// reads the resolutions, position limits and maximum speeds, and selects independent position
// control. Every exchange has a timeout; failures come back as HeadResult.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "tracking/head/pan_tilt_head.h"
#include "tracking/head/serial_line.h"

namespace linetrack {

struct PtuOptions {
  std::string device;            // serial device, e.g. /dev/ttyUSB0
  int baud = 9600;               // the unit's factory setting
  double reply_timeout_s = 0.5;  // longest wait for one reply
  // Signs from unit counts to the project's joint conventions: +1 when positive pan counts turn
  // the camera counter-clockwise seen from above; -1 when positive tilt counts raise it (the
  // D46). Check on your unit with a small move and docs/live.md.
  int pan_sign = 1;
  int tilt_sign = -1;
  double move_speed_fraction = 0.5;  // speed of MoveTo, as a fraction of the maximum speeds

  bool Check(std::string* why) const;
};

// What the unit told at start-up (counts, arc-seconds per count, counts per second).
struct PtuUnitInfo {
  double pan_resolution_arcsec = 0.0, tilt_resolution_arcsec = 0.0;
  long pan_min = 0, pan_max = 0, tilt_min = 0, tilt_max = 0;
  long pan_max_speed = 0, tilt_max_speed = 0;
};

class PtuDriver : public PanTiltHead {
 public:
  // Opens and initialises the unit; nullptr with *result saying why (kIoError: the device cannot
  // be opened; kTimeout: no answer; kRejected: an answer that makes no sense).
  static std::unique_ptr<PtuDriver> Open(const PtuOptions& options, HeadResult* result);
  ~PtuDriver() override;

  std::string Describe() const override;
  HeadLimits Limits() const override;
  HeadResult Read(HeadState* state) override;
  HeadResult MoveTo(double pan, double tilt) override;
  HeadResult SetVelocity(double pan_rate, double tilt_rate) override;
  HeadResult Stop() override;

  const PtuUnitInfo& unit() const { return unit_; }
  // Limit events ("!P", "!T") received since opening.
  int pan_limit_events() const;
  int tilt_limit_events() const;

 private:
  explicit PtuDriver(const PtuOptions& options) : options_(options) {}
  HeadResult Initialise();
  // Sends the commands in one write and reads one reply per command. replies[i] gets the text
  // of command i's reply; the first '!' reply makes the result kRejected (the other replies are
  // still read, keeping the line in step).
  HeadResult Transact(const std::vector<std::string>& commands, std::vector<std::string>* replies);
  // Takes limit events and stale replies (after a timeout) off the line.
  void DrainLocked();
  void CountEvents(int pan, int tilt);
  HeadResult EnsureMode(HeadMode mode);

  PtuOptions options_;
  PtuUnitInfo unit_;
  HeadLimits limits_;
  mutable std::mutex mutex_;
  SerialLine line_;
  HeadMode mode_ = HeadMode::kPosition;
  double target_pan_counts_ = 0.0, target_tilt_counts_ = 0.0;  // last MoveTo
  double pan_rate_ = 0.0, tilt_rate_ = 0.0;                    // last SetVelocity (rad/s)
  int pan_events_ = 0, tilt_events_ = 0;
  bool pan_stopped_by_limit_ = false, tilt_stopped_by_limit_ = false;
};

}  // namespace linetrack
