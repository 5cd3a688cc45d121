#include "app/global_mode_flags.h"

#include "models/errors.h"

namespace linetrack::app {

GlobalRecoveryOptions GlobalModeFlags::Options() const {
  if (kidnap_after_frames != kNotGiven) {
    throw InputError(
        "--kidnap-after: the trigger is now in seconds: --kidnap-after-s (default 0.3, 3 frames "
        "at 10 frames/s)");
  }
  if (global_after_frames != kNotGiven) {
    throw InputError(
        "--global-after: the trigger is now in seconds: --global-after-s (default 2.5, 25 frames "
        "at 10 frames/s)");
  }
  if (!(kidnap_after_s >= 0.0)) {
    throw InputError("--kidnap-after-s: must be >= 0 seconds (0: off)");
  }
  if (!(global_after_s >= 0.0)) {
    throw InputError("--global-after-s: must be >= 0 seconds (0: off)");
  }
  if (!(global_after_m >= 0.0)) throw InputError("--global-after-m: must be >= 0 metres (0: off)");
  GlobalRecoveryOptions options;
  options.enabled = !no_global;
  options.kidnap_s = kidnap_after_s;
  options.lost_s = global_after_s;
  options.lost_distance_m = global_after_m;
  return options;
}

void AddGlobalModeFlags(CLI::App* cmd, GlobalModeFlags* flags) {
  cmd->add_option("--kidnap-after-s", flags->kidnap_after_s,
                  "Global mode (the robot may have been carried away) after this many seconds of "
                  "frames (at least 2) that the matcher cannot place around the odometry's prior "
                  "and the global mode places elsewhere; frames counted from their stamps (0: off)")
      ->capture_default_str();
  cmd->add_option("--global-after-s", flags->global_after_s,
                  "Global mode after this many seconds lost (0: off)")
      ->capture_default_str();
  cmd->add_option("--global-after-m", flags->global_after_m,
                  "Global mode after this many metres driven while lost (0: off)")
      ->capture_default_str();
  cmd->add_flag("--no-global", flags->no_global,
                "No global mode: a lost robot searches only around the odometry's prior");
  // The former frame counts: refused with the flag in seconds that replaces each.
  cmd->add_option("--kidnap-after", flags->kidnap_after_frames)->group("");
  cmd->add_option("--global-after", flags->global_after_frames)->group("");
}

}  // namespace linetrack::app
