// Pan-tilt heads from spec strings, as the command line gives them (`--head`):
//   ptu:/dev/ttyUSB0   a FLIR/Directed Perception PTU on that serial port (ptu_driver.h)
//   sim                the simulated head (simulated_head.h; the caller steps its clock)
#pragma once

#include <memory>
#include <string>

#include "tracking/head/pan_tilt_head.h"
#include "tracking/head/ptu_driver.h"
#include "tracking/head/simulated_head.h"

namespace linetrack {

enum class HeadKind { kPtu, kSim };

struct HeadSpec {
  HeadKind kind = HeadKind::kSim;
  std::string device;  // serial device for kPtu
};

// Parses a head spec; throws InputError naming it when malformed.
HeadSpec ParseHeadSpec(const std::string& spec);

struct HeadOptions {
  PtuOptions ptu;  // device is taken from the spec
  SimulatedHeadOptions sim;
};

// Opens the head the spec names. Throws InputError for a bad spec, bad options, or a serial
// device that cannot be opened (missing, no permission); std::runtime_error when the unit does
// not answer or answers nonsense. A simulated head comes back as a SimulatedHead (dynamic_cast
// it to step its clock).
std::unique_ptr<PanTiltHead> OpenHead(const std::string& spec, const HeadOptions& options);

}  // namespace linetrack
