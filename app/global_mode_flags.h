// Flags of the global mode of a lost robot shared by `linetrack replay` and `linetrack live`
// (tracking/tracker/global_recovery.h, docs/global.md "Kidnapped-robot recovery").
#pragma once

#include <CLI/CLI.hpp>
#include <limits>

#include "tracking/tracker/global_recovery.h"

namespace linetrack::app {

// The flag values, as given on the command line: the triggers in seconds and metres (the engine
// derives the frame counts from the frames' stamps).
struct GlobalModeFlags {
  double kidnap_after_s = GlobalRecoveryOptions().kidnap_s;
  double global_after_s = GlobalRecoveryOptions().lost_s;
  double global_after_m = GlobalRecoveryOptions().lost_distance_m;
  bool no_global = false;
  // The frame counts of the former --kidnap-after and --global-after, refused with the flag
  // that replaces them (kNotGiven: not given).
  static constexpr int kNotGiven = std::numeric_limits<int>::min();
  int kidnap_after_frames = kNotGiven;
  int global_after_frames = kNotGiven;

  // The options; throws InputError naming the flag at fault.
  GlobalRecoveryOptions Options() const;
};

// Registers --kidnap-after-s, --global-after-s, --global-after-m and --no-global on `cmd`.
void AddGlobalModeFlags(CLI::App* cmd, GlobalModeFlags* flags);

}  // namespace linetrack::app
