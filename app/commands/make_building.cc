// `linetrack make-building OUT.cao`: writes the generated office building (models/
// synthetic_building.h); models/building.cao is its default.
#include <iostream>
#include <memory>

#include "app/commands.h"
#include "models/cao_writer.h"
#include "models/synth/synthetic_building.h"

namespace linetrack::app {
namespace {

struct MakeBuildingOptions {
  std::string out_path;
  BuildingSpec spec;
};

int RunMakeBuilding(const MakeBuildingOptions& opt) {
  const SyntheticBuilding building = GenerateBuilding(opt.spec);
  int rooms = 0;
  for (const BuildingSpace& space : building.spaces)
    rooms += space.corridor ? 0 : 1;
  const std::string title = "Office building: " + std::to_string(opt.spec.storeys) + " storeys, " +
                            std::to_string(rooms) +
                            " rooms on corridors; written by `linetrack make-building`; "
                            "world frame: metres, z up";
  WriteFileAtomically(opt.out_path, CaoText(building.cao, title));
  std::cout << "wrote " << opt.out_path << ": " << rooms << " rooms and "
            << building.spaces.size() - rooms << " corridors on " << opt.spec.storeys
            << " storeys, " << building.cao.points.size() << " points, "
            << building.cao.lines.size() << " lines, " << building.cao.faces.size() << " faces"
            << std::endl;
  return kExitOk;
}

}  // namespace

void AddMakeBuilding(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<MakeBuildingOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "make-building",
      "Writes a generated office building (.cao): rooms on both sides of a corridor per storey, "
      "thick walls, door openings, windows, pillars, cabinets, floors and ceilings");
  cmd->add_option("out", opt->out_path, "Output .cao file")->required();
  cmd->add_option("--storeys", opt->spec.storeys, "Storeys")->capture_default_str();
  cmd->add_option("--rooms-per-side", opt->spec.rooms_per_side,
                  "Rooms on each side of each corridor")
      ->capture_default_str();
  cmd->callback([opt, action] { *action = [opt] { return RunMakeBuilding(*opt); }; });
}

}  // namespace linetrack::app
