// linetrack: localise, track and servo robot cameras against a 3D wireframe model.
// One binary, one subcommand per job; exit codes in app/cli_common.h.
#include "app/cli.h"

int main(int argc, char** argv) {
  return linetrack::app::RunLinetrack(argc, argv);
}
