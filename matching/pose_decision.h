// The decision among verified poses: which one is the answer (ranking, ambiguity, the evidence
// a pose needs), the rivals a pose hinging on one correspondence has, and the pairs its
// covariance leans on.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "matching/unreported_doubt.h"
#include "matching/verification.h"

namespace linetrack {

// The evidence (nats) a verified pose needs not to be a chance alignment: chance_nats plus
// ln(V_prior / V_pose), V_prior = pi delta_t^2 2 delta_phi the prior's volume in (x, y, heading)
// and V_pose = (2 pi)^(3/2) sqrt(det C) the pose's (C its covariance): the number of distinct
// poses the search could have found by chance.
double RequiredEvidence(const VerificationContext& context, const VerificationOptions& options,
                        const VerifiedPose& verified);

// Orders verified poses: plausible first, then the larger evidence.
bool BetterThan(const VerifiedPose& a, const VerifiedPose& b);

// True when two poses are the same answer (within same_pose_m and same_pose_deg).
bool SamePose(const Pose3Dof& a, const Pose3Dof& b, const VerificationOptions& options);

// The refinement of a verified pose over the pairs it can lean on: `reported` (its reported
// correspondences) and those of its other pairs whose leverage at its pose (largest eigenvalue of
// W J_i C J_i' W') is below options.max_unreported_leverage, refitted from its pose (all the
// high-leverage unreported pairs left out at once); its own refinement when none is left out. An
// unreported pair that alone fixes a direction of the pose cannot be tested (OutlyingPair): the
// precision it gives is not the answer's. `kept`, when given, receives the pairs of the
// refinement.
PoseRefinementResult LowLeverageRefinement(const VerificationContext& context,
                                           const VerificationOptions& options,
                                           const VerifiedPose& verified,
                                           const std::vector<std::pair<int, int>>& reported,
                                           std::vector<std::pair<int, int>>* kept = nullptr);

// The poses a verified pose's pairs give without one of its influential pairs (the first-order
// deleted pose distinct from it, or beyond its uncertainty: Cook's distance above the
// hypothesis_quantile of chi2(3)), each refined and verified by Rematch without that pair
// (evidence lines term only). A pose that hinges on one correspondence has the pose of the
// others as a rival explanation, which the tree does not verify (a subset of a verified leaf).
std::vector<VerifiedPose> LeaveOneOutRivals(const VerificationContext& context,
                                            const VerificationOptions& options,
                                            const VerifiedPose& verified);

// The decision's steps, in the order the localizer takes them.

// Ranks verified poses for the decision (BetterThan), the plausible ones' evidence completed,
// with the leave-one-out rivals of the best joining them. False, with the reason, when there is
// no pose or no plausible one.
bool RankPoses(const VerificationContext& context, const VerificationOptions& options,
               std::vector<VerifiedPose>* verified, std::string* why);

// The distinct plausible poses of ranked verified poses, best first: each the best of the poses
// SamePose as it (indices into `ranked`, which is not empty).
std::vector<size_t> DistinctPoses(const std::vector<VerifiedPose>& ranked,
                                  const VerificationOptions& options);

// True when the best of ranked poses (`ranked` front, `distinct` from DistinctPoses) explains
// the lines clearly better than every other distinct pose: by ambiguity_nats over the second
// distinct plausible pose and over every distinct unobservable one (plausible but for its
// observability or held at the prior's border, whose evidence this completes). Else the reason.
bool ClearlyBest(const VerificationContext& context, const VerificationOptions& options,
                 const std::vector<size_t>& distinct, std::vector<VerifiedPose>* ranked,
                 std::string* why);

// The accepted pose's covariance (heading, x, y, scale): that of the pairs it can lean on
// (LowLeverageRefinement; its own when they leave the pose unobservable), averaged over what its
// unreported pairs are when options.doubt_unreported_pairs (DoubtedCovariance, whose groups
// `groups` receives).
Eigen::Matrix4d AnswerCovariance(const VerificationContext& context,
                                 const VerificationOptions& options, const VerifiedPose& best,
                                 const std::vector<std::pair<int, int>>& reported,
                                 std::vector<DoubtedGroup>* groups);

}  // namespace linetrack
