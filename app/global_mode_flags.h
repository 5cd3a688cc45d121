// Flags of the global mode of a lost robot shared by `linetrack replay` and `linetrack live`
// (tracking/tracker/global_recovery.h, docs/global.md "Kidnapped-robot recovery").
#pragma once

#include <CLI/CLI.hpp>

#include "tracking/tracker/global_recovery.h"

namespace linetrack::app {

// The flag values, as given on the command line.
struct GlobalModeFlags {
  int kidnap_after = GlobalRecoveryOptions().kidnap_frames;
  int global_after = GlobalRecoveryOptions().lost_frames;
  double global_after_m = GlobalRecoveryOptions().lost_distance_m;
  bool no_global = false;

  // The options; throws InputError naming the flag at fault.
  GlobalRecoveryOptions Options() const;
};

// Registers --kidnap-after, --global-after, --global-after-m and --no-global on `cmd`.
void AddGlobalModeFlags(CLI::App* cmd, GlobalModeFlags* flags);

}  // namespace linetrack::app
