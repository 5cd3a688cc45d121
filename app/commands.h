// The subcommands of `linetrack`. Each Add* registers one subcommand on `cli`; when the user
// picks it, its callback stores the job in *action, which main() runs after parsing.
#pragma once

#include "app/cli_common.h"
#include "app/recording.h"

namespace linetrack::app {

void AddModelInfo(CLI::App& cli, CommandAction* action);
void AddLocalize(CLI::App& cli, CommandAction* action);
void AddRender(CLI::App& cli, CommandAction* action);
void AddBenchCapture(CLI::App& cli, CommandAction* action);
void AddBenchMatch(CLI::App& cli, CommandAction* action);
void AddSynth(CLI::App& cli, CommandAction* action);
void AddCalibrate(CLI::App& cli, CommandAction* action);
void AddBenchCalibrate(CLI::App& cli, CommandAction* action);
void AddBenchLines(CLI::App& cli, CommandAction* action);
void AddLines(CLI::App& cli, CommandAction* action);
void AddBenchLocalizeImage(CLI::App& cli, CommandAction* action);
void AddBenchTrack(CLI::App& cli, CommandAction* action);
void AddBenchDrive(CLI::App& cli, CommandAction* action);
// `replay` of videos and image sequences; with `open_recording`, also of rosbag files.
void AddReplay(CLI::App& cli, CommandAction* action);
void AddReplayWithRecordings(CLI::App& cli, CommandAction* action, RecordingOpener open_recording);
void AddLive(CLI::App& cli, CommandAction* action);
void AddBenchServo(CLI::App& cli, CommandAction* action);
void AddCalibrateMount(CLI::App& cli, CommandAction* action);
void AddMakeBuilding(CLI::App& cli, CommandAction* action);
void AddModelImport(CLI::App& cli, CommandAction* action);
void AddBenchBuilding(CLI::App& cli, CommandAction* action);
void AddBenchMount(CLI::App& cli, CommandAction* action);
void AddHeading(CLI::App& cli, CommandAction* action);
void AddBenchHeading(CLI::App& cli, CommandAction* action);
void AddViews(CLI::App& cli, CommandAction* action);
void AddBenchViews(CLI::App& cli, CommandAction* action);

}  // namespace linetrack::app
