// Camera heading (and tilt when it is not known) from vanishing points, after the LUCAS robot
// (Behan and O'Keeffe 2005): the images of vertical edges meet at the vertical vanishing point,
// those of one horizontal direction of the building at a point of the horizon. Instead of the
// paper's pairwise intersections, every segment votes for the rotations (heading, tilt; zero
// roll) under which it points at one of the model's directions, a Hough vote over the Gauss
// sphere restricted to the model's directions; the best peak is refined by least squares on
// the segments' angles. The heading is known modulo the building's symmetries. docs/heading.md.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "matching/heading/model_directions.h"
#include "models/camera.h"
#include "models/geometry.h"

namespace linetrack {

struct HeadingOptions {
  // Noise of a segment's endpoints across the segment (pixels): its angle has standard deviation
  // sqrt(2) sigma / length.
  double endpoint_sigma_px = 1.0;
  // Noise of the whole line beside its endpoints' (0 for a detector's lines): a rotation about
  // its midpoint (degrees) and a shift across it (pixels), both standard deviations, as in
  // LineNoise; they add in quadrature to the endpoints' sqrt(2) sigma / length and sigma / sqrt(2).
  double line_angle_sigma_deg = 0.0;
  double line_offset_sigma_px = 0.0;
  // A segment points at a vanishing point when its angle to the direction toward it is within
  // max(gate_sigmas x its angle's standard deviation, min_gate_deg).
  double gate_sigmas = 3.0;
  double min_gate_deg = 0.3;
  // Shorter segments are ignored (pixels).
  double min_length_px = 20.0;
  // Segments whose horizontal bearing is this uncertain (degrees, one standard deviation) do not
  // vote for a heading: those along the horizon contain every horizontal direction.
  double max_bearing_sigma_deg = 10.0;
  // The vote treats a bearing as at least this uncertain (degrees): errors the segment's noise
  // does not cover (the tilt, the model's straightness, the detector's bias).
  double min_bearing_sigma_deg = 0.5;
  // Prior probability that a segment images none of the model's directions (the vote's and the
  // refinement's inlier-outlier mixture).
  double outlier_probability = 0.5;
  // Segments that must agree on a horizontal vanishing point for a heading.
  int min_support = 2;
  // With the tilt unknown: segments (vertical and horizontal) that must agree on it.
  int min_tilt_support = 4;
  // Heading accumulator bin (degrees) and the tilt range and step searched when the tilt is not
  // given (degrees, positive looking down).
  double bin_deg = 0.1;
  double tilt_min_deg = -30.0, tilt_max_deg = 45.0, tilt_step_deg = 0.5;
  // Heading hypotheses kept (peaks of the vote, best first), at least this far apart (degrees,
  // modulo the building's symmetries).
  int max_hypotheses = 6;
  double peak_separation_deg = 3.0;
  // Gauss-Newton iterations of the refinement of each inlier set, and rounds of re-selecting
  // the inliers at the refined rotation.
  int refine_iterations = 10;
  int refine_rounds = 3;

  bool Check(std::string* why) const;
};

// A vanishing point of the answer: the world direction, its image and the segments meeting there.
struct VanishingPoint {
  bool vertical = false;
  // Horizontal: index into ModelDirections::angles (the first heading candidate's assignment);
  // its bearing to the right of the optical axis in the level frame (radians, [-pi/2, pi/2)).
  int model_direction = -1;
  double bearing = 0.0;
  Eigen::Vector3d direction_cam = Eigen::Vector3d::Zero();  // unit, camera frame
  std::optional<Eigen::Vector2d> pixel;  // undistorted pixels; nullopt: at infinity
  std::vector<int> lines;                // indices of the supporting segments
};

// One peak of the heading vote with its symmetric copies.
struct HeadingHypothesis {
  // Headings (radians, [0, 2 pi), ascending) the peak's vanishing points cannot tell apart: the
  // refined heading plus the building's symmetries and the half turn.
  std::vector<double> headings;
  double heading = 0.0;        // the refined peak itself (radians, [0, pi))
  double heading_sigma = 0.0;  // standard deviation (radians), from the refinement
  int support = 0;             // horizontal segments pointing at the model's directions
  double rms_sigmas = 0.0;     // RMS of their angle residuals in standard deviations
};

// What EstimateHeading found. Expected failures are results: found == false with a reason.
struct HeadingCandidates {
  bool found = false;
  std::string reason;  // why not, when !found
  // Peaks of the vote, most supported first; hypotheses[0] is the answer.
  std::vector<HeadingHypothesis> hypotheses;
  double tilt = 0.0;  // radians, given or estimated
  double tilt_sigma = 0.0;
  bool tilt_estimated = false;
  int vertical_lines = 0;  // segments pointing at the vertical vanishing point
  std::vector<VanishingPoint> vanishing_points;  // of hypotheses[0]: vertical first
  int lines_used = 0;                            // segments at least min_length_px long

  // Headings (radians) of every hypothesis as well supported as the best: the candidates.
  std::vector<double> BestHeadings() const;
};

// Heading candidates from undistorted segments seen by `camera` (undistorted model) with the
// building's horizontal `directions`. `tilt` in radians when known (head encoder), else
// estimated. Throws InputError when the options are invalid, `directions` is empty, or a
// segment is not finite.
HeadingCandidates EstimateHeading(const std::vector<Segment2>& lines,
                                  const CameraIntrinsics& camera, std::optional<double> tilt,
                                  const ModelDirections& directions,
                                  const HeadingOptions& options = {});

}  // namespace linetrack
