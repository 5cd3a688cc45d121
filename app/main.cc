// linetrack: localise, track and servo robot cameras against a 3D wireframe model.
// One binary, one subcommand per job; exit codes in app/cli_common.h.
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

namespace {

std::string VersionText() {
  return "linetrack " LINETRACK_VERSION " (ViSP " + std::to_string(VISP_VERSION_MAJOR) + "." +
         std::to_string(VISP_VERSION_MINOR) + "." + std::to_string(VISP_VERSION_PATCH) +
         ", OpenCV " CV_VERSION ", Aravis " + std::to_string(arv_get_major_version()) + "." +
         std::to_string(arv_get_minor_version()) + "." + std::to_string(arv_get_micro_version()) +
         ")";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace linetrack;
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

  app::CommandAction action;
  app::AddModelInfo(cli, &action);
  app::AddLocalize(cli, &action);
  app::AddRender(cli, &action);
  app::AddBenchCapture(cli, &action);
  app::AddBenchMatch(cli, &action);
  app::AddSynth(cli, &action);
  app::AddCalibrate(cli, &action);
  app::AddBenchCalibrate(cli, &action);
  app::AddBenchLines(cli, &action);
  app::AddLines(cli, &action);
  app::AddBenchLocalizeImage(cli, &action);
  app::AddBenchTrack(cli, &action);
  app::AddBenchDrive(cli, &action);
  app::AddReplayWithRecordings(cli, &action, app::OpenRosBag);
  app::AddLive(cli, &action);
  app::AddBenchServo(cli, &action);
  app::AddRos(cli, &action);
  app::AddBenchRos(cli, &action);
  app::AddCalibrateMount(cli, &action);
  app::AddMakeBuilding(cli, &action);
  app::AddModelImport(cli, &action);
  app::AddBenchBuilding(cli, &action);
  app::AddBenchMount(cli, &action);
  app::AddHeading(cli, &action);
  app::AddBenchHeading(cli, &action);
  app::AddViews(cli, &action);
  app::AddBenchViews(cli, &action);

  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return cli.exit(e);
    std::cerr << "linetrack: " << e.what() << " (see linetrack --help)" << std::endl;
    return app::kExitBadInput;
  }
  if (quiet) spdlog::set_level(spdlog::level::err);
  app::SetStrictModelChecks(strict);
  try {
    return action ? action() : app::kExitBadInput;
  } catch (const InputError& e) {
    std::cerr << "linetrack: " << e.what() << std::endl;
    return app::kExitBadInput;
  } catch (const vpException& e) {
    std::cerr << "linetrack: ViSP error: " << e.getMessage() << std::endl;
    return app::kExitJobFailed;
  } catch (const std::exception& e) {
    std::cerr << "linetrack: error: " << e.what() << std::endl;
    return app::kExitJobFailed;
  }
}
