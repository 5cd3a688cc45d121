#include "app/global_mode_flags.h"

#include "models/errors.h"

namespace linetrack::app {

GlobalRecoveryOptions GlobalModeFlags::Options() const {
  if (kidnap_after < 0) throw InputError("--kidnap-after: must be >= 0 frames (0: off)");
  if (global_after < 0) throw InputError("--global-after: must be >= 0 frames (0: off)");
  if (!(global_after_m >= 0.0)) throw InputError("--global-after-m: must be >= 0 metres (0: off)");
  GlobalRecoveryOptions options;
  options.enabled = !no_global;
  options.kidnap_frames = kidnap_after;
  options.lost_frames = global_after;
  options.lost_distance_m = global_after_m;
  return options;
}

void AddGlobalModeFlags(CLI::App* cmd, GlobalModeFlags* flags) {
  cmd->add_option("--kidnap-after", flags->kidnap_after,
                  "Global mode (the robot was carried away) after this many lost frames in a row "
                  "whose lines the matcher around the odometry's prior cannot explain (0: off)")
      ->capture_default_str();
  cmd->add_option("--global-after", flags->global_after,
                  "Global mode after this many lost frames (0: off)")
      ->capture_default_str();
  cmd->add_option("--global-after-m", flags->global_after_m,
                  "Global mode after this many metres driven while lost (0: off)")
      ->capture_default_str();
  cmd->add_flag("--no-global", flags->no_global,
                "No global mode: a lost robot searches only around the odometry's prior");
}

}  // namespace linetrack::app
