// Checks of a loaded model that catch what would otherwise fail silently (docs/models.md): a model
// the matcher cannot use well, or that does not say what its author meant. Library code: the
// findings are returned; app/ prints them (or refuses the model with --strict).
#pragma once

#include <string>
#include <vector>

#include "models/wireframe.h"

namespace linetrack {

enum class FindingKind {
  kNoVerticalEdges,  // the matcher's first stage needs vertical edges
  kNoFreeSpace,      // no face encloses a free space: the navigable area is a fallback
  kOpenWalls,        // wall ends open to the outside: a missing wall leaves a space open
  kStrayLine,        // a 3D line on no face
  kDegenerateFace,   // a face without area
  kNonPlanarFace,    // a face whose corners are off its plane
  kSelfIntersectingFace,
  kImplausibleExtent,  // far too wide for metres (millimetres?)
  kFarFromOrigin,      // georeferenced coordinates lose precision
  kShortEdges,         // edges whose images are too short for the matcher
};

struct ModelFinding {
  FindingKind kind = FindingKind::kNoVerticalEdges;
  std::string message;  // "model.cao: what is wrong and what it causes"
};

struct ModelCheckOptions {
  double on_face_tolerance = 0.01;      // a 3D line lies on a face within this (metres)
  double planar_tolerance = 1e-3;       // a face's corners lie on its plane within this (metres)
  double max_extent = 1000.0;           // a wider model is probably not in metres (metres)
  double max_origin_distance = 1000.0;  // metres from the origin to the model's centre
  // The short-edge check: an edge seen from viewing_distance metres by a camera of focal_px
  // pixels must be at least min_image_length_px long in the image.
  double focal_px = 1000.0;
  double viewing_distance = 3.0;
  double min_image_length_px = 15.0;

  bool Check(std::string* why) const;
};

// Every finding for `model` (empty: nothing to say). Throws InputError when the options are
// invalid.
std::vector<ModelFinding> CheckModel(const WireframeModel& model,
                                     const ModelCheckOptions& options = {});

// Distance (metres) from p to the face's polygon (its plane inside the polygon, else its border).
double DistanceToFace(const ModelFace& face, const Eigen::Vector3d& p);

// True when two non-adjacent sides of the polygon (in its plane) cross or touch.
bool SelfIntersecting(const ModelFace& face);

}  // namespace linetrack
