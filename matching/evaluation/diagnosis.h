// Diagnosis of a localisation against its ground truth (synthetic scenes): the true
// correspondences followed through every stage of the matcher -- candidate edges (view-invariant
// regions), unary constraints (residuals in standard deviations of the noise model), the feasible
// region of the truth's hypothesis, its verification and its evidence. For benchmarks and tests.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "matching/localizer.h"
#include "models/synth/synthetic_scenes.h"

namespace linetrack {

// One true correspondence (model edge id, line index) through the stages.
struct TruthPairCheck {
  int edge_id = -1;
  int line = -1;
  bool vertical = false;
  bool candidate = false;      // the edge is among the candidate edges of the prior
  bool vertical_line = false;  // vertical edge: the line passed the "can be vertical" test
  bool unary_pass = false;     // passes the unary constraint of its kind
  // Residuals at the true pose in standard deviations of the noise model. Non-vertical edge:
  // g1 (direction) and the distance of the true position to the position line. Vertical edge:
  // nL_y (the vertical-line test) and the bearing.
  double first_sigmas = 0.0;
  double second_sigmas = 0.0;
  // At the truth's verified pose: eq. 9 distance (pixels) of the line to its edge's projection
  // (+inf when out of view), and whether guided matching kept the pair.
  double distance_px = 0.0;
  bool guided = false;
};

struct TruthDiagnosis {
  std::vector<TruthPairCheck> pairs;
  int true_edges = 0;       // distinct model edges imaged
  int candidate_edges = 0;  // of which are candidates
  int unary_edges = 0;      // of which have a line passing the unary constraint
  // The truth's hypothesis (each true edge with its longest line passing the unary constraint):
  // does its feasible region stay non-empty? If not, the edge whose cut emptied it.
  bool region_consistent = false;
  int region_emptied_by = -1;
  bool region_contains_truth = false;  // some bin holds the true heading and position
  // The truth verified as the matcher verifies a hypothesis, from the true pose.
  bool plausible = false;
  std::string implausible_because;
  int matched_edges = 0;
  double rms_px = 0.0;
  double evidence_score = 0.0;
  // Observability of the pose from all true correspondences at the true pose (1 px noise).
  double position_sigma_m = 0.0;
  double heading_sigma_deg = 0.0;
};

// The localisation problem of a synthetic scene (its lines, prior, height and tilt).
LocalizationProblem ProblemOf(const SyntheticScene& scene);

// Runs the checks for `problem` whose truth is `truth` with correspondences `truth_matches`
// (model edge id, line index).
TruthDiagnosis DiagnoseTruth(const Localizer& localizer, const LocalizationProblem& problem,
                             const Pose3Dof& truth,
                             const std::vector<std::pair<int, int>>& truth_matches);

}  // namespace linetrack
