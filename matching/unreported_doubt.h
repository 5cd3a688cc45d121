// The accepted pose's covariance averaged over what its unreported pairs are (law of total
// covariance): an unreported pair may be a clutter line that guided matching gave to an edge,
// and the pose is then the pose of the other pairs (docs/matching.md, section 3).
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "matching/verification.h"

namespace linetrack {

// The unreported pairs of one model edge, doubted together (two lines on one edge pin the same
// direction: taken out one at a time, each is replaced by the other).
struct DoubtedGroup {
  std::vector<std::pair<int, int>> pairs;  // (edge index, line index)
  // Posterior probability that every pair of the group is the edge's image, each from its
  // explanations at the pose without the group: e^l / (e^l + 1 + sum_rivals e^l_r), l its
  // log-likelihood ratio against clutter (prior odds included), the 1 for clutter; a rival line
  // another edge of the interpretation explains counts e^(l_r - l_other). Visibility, extent and
  // occlusion are those of the pose itself; ratios also beyond the gates.
  double probability_true = 1.0;
  // The pose without the group (heading, x, y, focal scale) minus the pose, and its covariance.
  Eigen::Vector4d shift = Eigen::Vector4d::Zero();
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  // The pairs of the group alone fix a direction of the pose (or leave it beyond the options'
  // observability limits): the pose without them is bounded by the prior region instead.
  bool bounded_by_prior = false;
};

// The pose of a refined pose's pairs without the pairs `removed` (indices into verified.pairs),
// to first order (Sherman-Morrison-Woodbury on the normal equations, whitened residuals r and
// Jacobian J of the removed pairs): covariance C' = C + C J' (I - J C J')^-1 J C = (C^-1 -
// J'J)^-1 and shift C' J' r; with `prior_information` P (non-zero) the increase is bounded by it,
// C' = C + (A - J'J)^-1 - A^-1 with A = C^-1 + P, and the shift (A - J'J)^-1 J' r (P centred at
// the pose). False when the information left is not positive definite.
bool DeletedGroupPose(const VerificationContext& context, const VerifiedPose& verified,
                      const std::vector<size_t>& removed, const Eigen::Matrix4d& prior_information,
                      Eigen::Vector4d* shift, Eigen::Matrix4d* covariance);

// The information (heading, x, y, scale) of a uniform prior region: 4 / radius^2 per position
// axis, 12 / width^2 in heading (the variances of a uniform disk and interval), none in scale.
Eigen::Matrix4d PriorInformation(const PriorRegion& prior);

// The covariance of a verified pose (heading, x, y, focal scale) averaged over its unreported
// pairs (those not in `reported`), grouped by edge: C + sum_G (1 - p_G) [(C_G - C) + d_G d_G'],
// p_G the group's probability_true, d_G and C_G the pose without it (first order in the
// doubt, groups independent). Its own covariance when every pair is reported. `groups`, when
// given, receives the doubted groups.
Eigen::Matrix4d DoubtedCovariance(const VerificationContext& context,
                                  const VerificationOptions& options, const VerifiedPose& verified,
                                  const std::vector<std::pair<int, int>>& reported,
                                  std::vector<DoubtedGroup>* groups = nullptr);

}  // namespace linetrack
