// A generated office building for benchmarks and tests (docs/models.md): storeys of rooms on both
// sides of a central corridor, walls with a thickness, a door opening from every room to the
// corridor (its two jambs and its head), windows drawn as 3D lines, pillars, cabinets and low
// boxes in the rooms, floors and ceilings. Every face is written facing the free space.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "models/cao_reader.h"

namespace linetrack {

struct BuildingSpec {
  int storeys = 2;
  int rooms_per_side = 9;
  double storey_height = 3.0;  // floor to ceiling (metres)
  double slab = 0.3;           // from a ceiling to the floor above (metres)
  double wall = 0.2;           // wall thickness (metres)
  double room_depth = 4.0;     // metres, across the corridor
  double corridor_width = 2.0;
  double door_width = 0.9, door_height = 2.1;

  bool Check(std::string* why) const;
};

// One space of the building: a room or a corridor, its free floor rectangle on its storey.
struct BuildingSpace {
  std::string name;  // e.g. "s0-south-3", "s1-corridor"
  int storey = 0;
  bool corridor = false;
  Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = Eigen::Vector2d::Zero();  // metres
  double floor_z = 0.0;
};

struct SyntheticBuilding {
  CaoModel cao;
  std::vector<BuildingSpace> spaces;  // the rooms storey by storey, then the corridors
};

// The whole building. Throws InputError when the spec is invalid.
SyntheticBuilding GenerateBuilding(const BuildingSpec& spec);

// Space `index` of GenerateBuilding(spec) modelled alone: its faces, furniture and windows, its
// door opening closed by a door leaf flush with the far side of the wall (a corridor alone has
// all its doors closed so). Throws InputError for an invalid spec or index.
CaoModel SpaceAlone(const BuildingSpec& spec, int index);

}  // namespace linetrack
