// The `linetrack` command line: every subcommand registered, the arguments parsed, the job run and
// its errors mapped to exit codes (app/cli_common.h). main() is this function alone.
#pragma once

namespace linetrack::app {

// Runs `linetrack` with argv[1..argc-1]; returns the exit code (0, 1 the job failed, 2 bad input).
int RunLinetrack(int argc, char** argv);

}  // namespace linetrack::app
