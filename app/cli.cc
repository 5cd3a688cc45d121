#include "app/cli.h"

#include <arv.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <visp3/core/vpConfig.h>
#include <visp3/core/vpException.h>
#include <exception>
#include <iostream>
#include <opencv2/core/version.hpp>

#include "app/commands.h"
#include "app/model_loading.h"
#include "app/ros/bag_recording.h"
#include "app/ros/ros_commands.h"
#include "models/errors.h"

namespace linetrack::app {

namespace {

std::string VersionText() {
  return "linetrack " LINETRACK_VERSION " (ViSP " + std::to_string(VISP_VERSION_MAJOR) + "." +
         std::to_string(VISP_VERSION_MINOR) + "." + std::to_string(VISP_VERSION_PATCH) +
         ", OpenCV " CV_VERSION ", Aravis " + std::to_string(arv_get_major_version()) + "." +
         std::to_string(arv_get_minor_version()) + "." + std::to_string(arv_get_micro_version()) +
         ")";
}

}  // namespace

int RunLinetrack(int argc, char** argv) {
  auto logger = spdlog::stderr_color_st("linetrack");
  logger->set_pattern("linetrack: %^%l%$: %v");
  spdlog::set_default_logger(logger);

  CLI::App cli{
      "linetrack: localise a robot camera from straight lines against a 3D wireframe model "
      "(.cao),\ntrack it with ViSP's moving edges, calibrate it, and run it live on a pan-tilt "
      "head.",
      "linetrack"};
  cli.set_version_flag("--version", VersionText(), "Print the version and exit");
  cli.require_subcommand(1);
  // Global flags (--quiet, --strict) are accepted after the subcommand too: its subcommands
  // (inheriting this) hand the options they do not know up to here.
  cli.fallthrough(true);
  bool quiet = false;
  cli.add_flag("-q,--quiet", quiet, "Only errors on stderr");
  bool strict = false;
  cli.add_flag("--strict", strict,
               "Refuse a model the checks find fault with (exit 2) instead of warning");

  CommandAction action;
  AddModelInfo(cli, &action);
  AddLocalize(cli, &action);
  AddRender(cli, &action);
  AddBenchCapture(cli, &action);
  AddBenchMatch(cli, &action);
  AddSynth(cli, &action);
  AddCalibrate(cli, &action);
  AddBenchCalibrate(cli, &action);
  AddBenchLines(cli, &action);
  AddLines(cli, &action);
  AddBenchLocalizeImage(cli, &action);
  AddBenchTrack(cli, &action);
  AddBenchDrive(cli, &action);
  AddReplayWithRecordings(cli, &action, OpenRosBag);
  AddLive(cli, &action);
  AddBenchServo(cli, &action);
  AddRos(cli, &action);
  AddBenchRos(cli, &action);
  AddCalibrateMount(cli, &action);
  AddMakeBuilding(cli, &action);
  AddModelImport(cli, &action);
  AddBenchBuilding(cli, &action);
  AddBenchMount(cli, &action);
  AddHeading(cli, &action);
  AddBenchHeading(cli, &action);
  AddViews(cli, &action);
  AddBenchViews(cli, &action);

  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return cli.exit(e);
    std::cerr << "linetrack: " << e.what() << " (see linetrack --help)" << std::endl;
    return kExitBadInput;
  }
  if (quiet) spdlog::set_level(spdlog::level::err);
  SetStrictModelChecks(strict);
  try {
    return action ? action() : kExitBadInput;
  } catch (const InputError& e) {
    std::cerr << "linetrack: " << e.what() << std::endl;
    return kExitBadInput;
  } catch (const vpException& e) {
    std::cerr << "linetrack: ViSP error: " << e.getMessage() << std::endl;
    return kExitJobFailed;
  } catch (const std::exception& e) {
    std::cerr << "linetrack: error: " << e.what() << std::endl;
    return kExitJobFailed;
  }
}

}  // namespace linetrack::app
