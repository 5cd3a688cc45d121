// Evidence in the image for a casing beside a frame line (docs/integrity.md, section 1.3): the
// outer border of a door or window casing is an unmodelled line parallel to the model's line, a
// few centimetres across it on the same face, onto which the moving edges may latch. Along the
// normal of the line's image at each of its edge points, a second gradient ridge at one width
// (metres on the face) for many points is a casing; a single sharp ridge on most points is none.
#pragma once

#include <visp3/core/vpImage.h>

#include <Eigen/Geometry>

#include "models/camera.h"
#include "tracking/tracker/edge_refinement.h"

namespace linetrack {

struct CasingEvidenceOptions {
  bool enabled = true;  // false: every frame line keeps its casing allowance
  // Widths (metres across the line, on its face) searched for the casing's outer border: real
  // door casings are 5-10 cm; the renderer paints 7 cm.
  double min_width_m = 0.02;
  double max_width_m = 0.12;
  double min_separation_px = 2.5;  // and at least this far from the line's own step (pixels)
  double max_search_px = 40.0;     // the search along the normal ends here (pixels)
  // A second ridge counts when its gradient is at least this share of the point's own step (and
  // at least min_gradient grey levels per pixel).
  double relative_strength = 0.25;
  double min_gradient = 3.0;
  // Widths agree when within this many pixels (at the point's scale) of each other.
  double width_tolerance_px = 1.5;
  // A point is examined when its own step is sharp (half-maximum width within the nearest width
  // searched) and the whole search lies in the image. With fewer examined points than
  // min_points or than min_examined_share of the edge's points, the image is not clear enough
  // to rule a casing out.
  int min_points = 6;
  double min_examined_share = 0.5;
  // A casing is seen when at least this share of the examined points show a ridge at one width.
  double min_ridge_share = 0.15;

  bool Check(std::string* why) const;
};

// kSeen: a parallel ridge at one width on many points; kAbsent: the edge's points were seen
// clearly and few show one; kUnclear: too few points could be examined (blur, image border).
enum class CasingVerdict { kSeen, kAbsent, kUnclear };

struct CasingEvidence {
  CasingVerdict verdict = CasingVerdict::kUnclear;
  int examined = 0;      // points whose profile was examined
  int with_ridge = 0;    // of those, points with a second ridge at the most common width
  double width_m = 0.0;  // that width (signed along edge.casing_direction), when any
};

// Looks for the casing of `edge` (its points and casing_direction, world) in the undistorted
// `image` seen from `cam_from_world` by the undistorted `camera`. kUnclear when the edge has no
// casing direction.
CasingEvidence FindCasing(const vpImage<unsigned char>& image, const CameraIntrinsics& camera,
                          const Eigen::Isometry3d& cam_from_world, const EdgeObservation& edge,
                          const CasingEvidenceOptions& options);

// Applies FindCasing to each observation with a casing direction and clears the direction of
// those whose verdict is kAbsent (their casing allowance is then not paid). Returns how many
// were cleared.
int ClearCasingsNotSeen(const vpImage<unsigned char>& image, const CameraIntrinsics& camera,
                        const Eigen::Isometry3d& cam_from_world,
                        const CasingEvidenceOptions& options,
                        std::vector<EdgeObservation>* observations);

}  // namespace linetrack
