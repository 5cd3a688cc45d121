// Orientation of a model's faces toward the free space they bound, whatever order the file wrote
// their points in: room walls, floors and ceilings face the room; pillars, boxes and thick walls
// face out of their solid; a face with free space on both sides faces where it is seen from
// (docs/models.md). Lines are never touched.
#pragma once

#include <string>
#include <vector>

#include "models/free_space.h"
#include "models/wireframe.h"

namespace linetrack {

// How a face's side was decided.
enum class OrientationRule {
  kDegenerate,   // no area: left as written
  kFreeSide,     // free space on one side only: faces it
  kOutsideSide,  // outside on one side, solid on the other (a facade): faces outside
  kSeenSide,     // free space on both sides: faces the side cameras in the free space see
  kTwoSided,     // free space on both sides, seen from both: kept, and seen from both sides
  kUndecided,    // no free space on either side, or seen from neither: kept as written
};

// The decision for one face.
struct FaceOrientation {
  bool flip = false;  // the file's point order is reversed
  OrientationRule rule = OrientationRule::kDegenerate;
  // What lies behind the face once oriented (kFreeSide): outside, a solid and why.
  SpaceAt behind;
};

struct FaceOrientationOptions {
  FreeSpaceOptions space;
  // Sample points are moved this far off the face to each side (metres).
  double side_offset = 1e-3;
  // Cameras that decide by sight stand at least this far from walls (metres), within this range
  // of the face, on a grid of this pitch, at heights floor + 0.5, 1.0, ... below the ceiling.
  double view_clearance = 0.3;
  double view_range = 8.0;
  double view_pitch = 0.5;
  // Both sides are seen (kTwoSided) when the less seen side has at least this share of the views
  // of the other.
  double two_sided_share = 0.1;
};

// Decides every face's side (one entry per face of `model`, whose faces and storeys are set; the
// faces' current point order is "as written"). Empty when the model encloses no free space at the
// navigation height of any storey: an object seen from outside (ViSP's cube), left as written.
std::vector<FaceOrientation> OrientFaces(const WireframeModel& model,
                                         const FaceOrientationOptions& options = {});

// Sentences for a report, one per kind of change, e.g. "12 wall faces turned to face the room";
// empty when nothing was turned and no face is two-sided or undecided.
std::vector<std::string> OrientationSummary(const WireframeModel& model,
                                            const std::vector<FaceOrientation>& orientation);

}  // namespace linetrack
