// The global mode's decision among the verified peaks' finalists: the answer, "ambiguous" with
// the rival poses, or no pose with the reason. Pure functions of the verifications, tested
// directly (docs/global.md, section 1, step 4).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "matching/global/global_localizer.h"

namespace linetrack {

// A finalist of one peak's verification: its pose, evidence, the share of its predicted visible
// outline it observes, and whether that verification accepted it.
struct Explanation {
  Pose3Dof pose;
  double score = 0.0;     // evidence (nats)
  double support = 0.0;   // PoseEvidence::Support
  int verification = -1;  // index into the verifications
  bool accepted = false;
};

// Every finalist of every verification (those that accepted no pose included), best first.
std::vector<Explanation> AllExplanations(const std::vector<PeakVerification>& verifications);

// The margin (nats) a far, well-supported rival must lose by: ambiguity_nats plus ln(N), N the
// verified peaks (at least 1): the best of N verifications is compared, so the odds of
// ambiguity_nats hold for the family of N (a union bound).
double FamilyMargin(double ambiguity_nats, int verified_peaks);

// The answer's covariance (heading rad, x m, y m) widened by the poses near it that explain the
// image almost as well: `covariance` plus sum_i w_i d_i d_i' / sum_i w_i over `near` (the answer
// itself with weight 1 included or not), w_i = exp(score_i - best_score), d_i = near_i - answer
// (heading wrapped): the second moment about the answer of the mixture of the near explanations.
Eigen::Matrix3d NearSpreadCovariance(const Pose3Dof& answer, const Eigen::Matrix3d& covariance,
                                     double best_score, const std::vector<Explanation>& near);

// True when `e` is near `best`: within options.near_m and options.near_deg (the same place seen
// with the position uncertainty of a few lines, not a rival place).
bool NearPose(const Pose3Dof& best, const Pose3Dof& e, const GlobalOptions& options);

// The decision (fills found, ambiguous, best, rivals and reason of *out from its verifications):
// - rivals are the distinct explanations not near the best within ambiguity_nats of it, and the
//   far ones its own verification accepted, observing min_support and at least the best's share
//   of their outline, within FamilyMargin: the evidence and the observed outline disagree;
// - with rivals: "ambiguous" (the best and the rivals listed); else the best is the answer when a
//   verification accepted it (or a pose the same as it), it observes min_support of its outline
//   and its covariance, widened by the near explanations within ambiguity_nats
//   (NearSpreadCovariance), stays within the observability limits of `vo`.
void DecideGlobal(const VerificationOptions& vo, const GlobalOptions& options, GlobalResult* out);

}  // namespace linetrack
