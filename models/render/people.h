// People walking through a rendered scene: moving, textured occluders the model knows nothing
// of. A person is three stacked boxes (legs, torso, head) facing the way it walks, with clothes'
// albedos, a striped shirt and a stronger texture than the walls.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "models/render/render_scene.h"

namespace linetrack {

// A straight walk at constant velocity between two times.
struct PersonWalk {
  Eigen::Vector2d start = Eigen::Vector2d::Zero();      // floor position at t_start (metres)
  Eigen::Vector2d velocity = Eigen::Vector2d::UnitX();  // m/s, not zero
  double t_start = 0.0, t_end = 0.0;                    // seconds in the scene
  double height = 1.75;                                 // metres
  uint64_t look = 0;                                    // seed of the albedos and stripes

  // Floor position at time t (extrapolated outside the walk).
  Eigen::Vector2d PositionAt(double t) const { return start + (t - t_start) * velocity; }
  bool InSceneAt(double t) const { return t >= t_start && t <= t_end; }
};

// The surfaces of the person at time t (kind kPerson; the stripes are decals on the torso);
// empty when the person is not in the scene at t.
std::vector<RenderSurface> PersonSurfaces(const PersonWalk& walk, double t);

}  // namespace linetrack
