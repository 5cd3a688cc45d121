// The dominant horizontal directions of a building, read from its model's edges: the angles
// (counter-clockwise from world +x, modulo pi) along which most of its horizontal edge length
// runs, and the rotations that map that set onto itself (the headings a vanishing point cannot
// tell apart). docs/heading.md.
#pragma once

#include <string>
#include <vector>

#include "models/wireframe.h"

namespace linetrack {

struct ModelDirectionOptions {
  // An edge is horizontal when its angle to the floor plane is below this (degrees).
  double horizontal_tolerance_deg = 2.0;
  // Edge directions closer than this (degrees, modulo 180) are one direction.
  double merge_deg = 2.0;
  // A direction is dominant when it holds at least this share of the horizontal edge length.
  double min_share = 0.05;

  bool Check(std::string* why) const;
};

// A set of horizontal directions, each an angle in [0, pi) with the edge length along it.
struct ModelDirections {
  std::vector<double> angles;   // radians, [0, pi), ascending
  std::vector<double> lengths;  // metres of horizontal edges along each

  // Rotations delta in [0, pi) (radians, ascending, 0 first) with {angles + delta} = {angles}
  // modulo pi within `tolerance` radians; with the half turn that no vanishing point can
  // resolve they give the headings one vanishing point leaves undecided.
  std::vector<double> Symmetries(double tolerance) const;
};

// The dominant horizontal directions of `model` (empty when it has no horizontal edge).
// Throws InputError naming the model when the options are invalid.
ModelDirections DominantDirections(const WireframeModel& model,
                                   const ModelDirectionOptions& options = {});

// Directions from explicit angles (radians, any range; merged within `merge` radians), e.g. for
// a building known to be rectangular: {0, pi/2}.
ModelDirections DirectionsFromAngles(const std::vector<double>& angles, double merge);

}  // namespace linetrack
