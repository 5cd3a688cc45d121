// Pan-tilt heads from spec strings, as the command line gives them (`--head`):
//   ptu:/dev/ttyUSB0   a FLIR/Directed Perception PTU on that serial port (ptu_driver.h)
//   sim                the simulated head (provided by whoever simulates it: see make_sim)
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "tracking/head/pan_tilt_head.h"
#include "tracking/head/ptu_driver.h"

namespace linetrack {

enum class HeadKind { kPtu, kSim };

struct HeadSpec {
  HeadKind kind = HeadKind::kSim;
  std::string device;  // serial device for kPtu
};

// Parses a head spec; throws InputError naming it when malformed.
HeadSpec ParseHeadSpec(const std::string& spec);

// Makes the simulated head (tracking/sim/simulated_head.h; the simulator lives elsewhere).
using SimHeadMaker = std::function<std::unique_ptr<PanTiltHead>()>;

struct HeadOptions {
  PtuOptions ptu;         // device is taken from the spec
  SimHeadMaker make_sim;  // empty: "sim" is refused with an InputError
};

// Opens the head the spec names. Throws InputError for a bad spec, bad options, or a serial
// device that cannot be opened (missing, no permission); std::runtime_error when the unit does
// not answer or answers nonsense. A simulated head is what make_sim returns (a SimulatedHead:
// dynamic_cast it to step its clock).
std::unique_ptr<PanTiltHead> OpenHead(const std::string& spec, const HeadOptions& options);

}  // namespace linetrack
