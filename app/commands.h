// The subcommands of `linetrack`. Each Add* registers one subcommand on `cli`; when the user
// picks it, its callback stores the job in *action, which main() runs after parsing.
#pragma once

#include "app/cli_common.h"

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
void AddReplay(CLI::App& cli, CommandAction* action);
void AddLive(CLI::App& cli, CommandAction* action);
void AddBenchServo(CLI::App& cli, CommandAction* action);
void AddHeading(CLI::App& cli, CommandAction* action);
void AddBenchHeading(CLI::App& cli, CommandAction* action);
void AddViews(CLI::App& cli, CommandAction* action);
void AddBenchViews(CLI::App& cli, CommandAction* action);

}  // namespace linetrack::app
