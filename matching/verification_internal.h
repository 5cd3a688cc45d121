// Pieces of the verification shared by its two source files (verification.cc and
// hypothesis_trimming.cc); not part of the matching library's interface.
#pragma once

#include <limits>
#include <utility>
#include <vector>

#include "matching/pose_refinement.h"
#include "matching/quantiles.h"
#include "matching/verification.h"

namespace linetrack {

// Pairs as LineMatches whitened by the noise model with levers from the segment's own middle
// (the projection is not known yet).
std::vector<LineMatch> ToLineMatches(const VerificationContext& context,
                                     const std::vector<std::pair<int, int>>& pairs);

// The verification's refinement options with the prior as bounds (PoseBounds): the prior disk
// and heading interval widened by the options' margins, as the plausibility check widens them.
PoseRefinementOptions RefinementOptions(const VerificationContext& context,
                                        const VerificationOptions& options);

// The explanations of a pair's line at a pose (covariance of heading, x, y, scale; the context's
// gates): the pair's log-likelihood ratio against clutter (nats, also when negative; -infinity
// when outside the gates there), those of its rival explanations (another edge for the line;
// another line for the edge that cannot be a fragment of the same image), and whether the edge
// has such fragments there likelier than clutter. `from` may move visibility, extent and
// occlusion to another pose, give the pair's ratio beyond the gates, and price rival lines that
// other pairs hold.
struct PairExplanations {
  double own = -std::numeric_limits<double>::infinity();
  std::vector<double> rivals;
  bool fragments = false;
};
struct ExplainFrom {
  // When given: the pose (focal scale seen_scale) that decides the edges' visibility, extent
  // (frustum clipping) and occlusion; the image lines and their uncertainty stay at `pose`.
  const Pose3Dof* seen = nullptr;
  double seen_scale = 1.0;
  // The pair's own ratio also beyond the gates (across the line and on its extent).
  bool beyond_gates = false;
  // When given: the interpretation's pairs (edge, line). A rival line that another edge holds
  // there would undo that pair (a line is one edge's image at most): its ratio minus the holder's.
  const std::vector<std::pair<int, int>>* held = nullptr;
};
PairExplanations ExplainPair(const VerificationContext& context, const VerificationOptions& options,
                             const Pose3Dof& pose, double scale, const Eigen::Matrix4d& covariance,
                             const std::pair<int, int>& pair, const ExplainFrom& from = {});

}  // namespace linetrack
