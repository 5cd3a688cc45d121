// Unmodelled clutter for synthetic scenes: boxes and cabinets standing against walls and posters
// hung on them, placed deterministically from a seed so that a line detector sees lines the
// model does not have.
#pragma once

#include <cstdint>
#include <vector>

#include "models/navigable_area.h"
#include "models/render/render_scene.h"
#include "models/wireframe.h"

namespace linetrack {

// Places up to `count` objects against the model's vertical faces, on the side where
// `free_space` has room: boxes and cabinets on the floor, shallower than the area's clearance
// (so that no allowed camera position lies inside one), and posters on the walls. Objects keep
// `margin` metres from the model's 3D lines (doors, windows) and from each other. Returns solid
// kClutter surfaces (posters' frames as decals on them); fewer objects when no room is left.
std::vector<RenderSurface> PlaceClutter(const WireframeModel& model,
                                        const NavigableArea& free_space, int count, double margin,
                                        uint64_t seed, int* placed = nullptr);

}  // namespace linetrack
