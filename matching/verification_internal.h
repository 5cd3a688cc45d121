// Pieces of the verification shared by its two source files (verification.cc and
// hypothesis_trimming.cc); not part of the matching library's interface.
#pragma once

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

}  // namespace linetrack
