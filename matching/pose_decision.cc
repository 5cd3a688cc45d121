#include "matching/pose_decision.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "matching/hypothesis_trimming.h"
#include "matching/quantiles.h"

namespace linetrack {

double RequiredEvidence(const VerificationContext& context, const VerificationOptions& options,
                        const VerifiedPose& verified) {
  if (context.prior == nullptr) return options.chance_nats;
  const PriorRegion& prior = *context.prior;
  const double prior_volume = kPi * std::max(prior.radius, 0.01) * std::max(prior.radius, 0.01) *
                              std::max(prior.heading.Width(), DegToRad(0.1));
  const double det = verified.refinement.covariance.topLeftCorner<3, 3>().determinant();
  if (!(det > 0.0) || !std::isfinite(det)) return std::numeric_limits<double>::infinity();
  const double pose_volume = std::pow(2.0 * kPi, 1.5) * std::sqrt(det);
  return options.chance_nats + std::max(0.0, std::log(prior_volume / pose_volume));
}

bool BetterThan(const VerifiedPose& a, const VerifiedPose& b) {
  if (a.plausible != b.plausible) return a.plausible;
  return a.evidence.Score() > b.evidence.Score();
}

bool SamePose(const Pose3Dof& a, const Pose3Dof& b, const VerificationOptions& options) {
  return std::hypot(a.x - b.x, a.y - b.y) <= options.same_pose_m &&
         std::abs(WrapAngle(a.heading - b.heading)) <= DegToRad(options.same_pose_deg);
}

PoseRefinementResult LowLeverageRefinement(const VerificationContext& context,
                                           const VerificationOptions& options,
                                           const VerifiedPose& verified,
                                           const std::vector<std::pair<int, int>>& reported,
                                           std::vector<std::pair<int, int>>* kept_pairs) {
  const std::vector<LineMatch> matches = ToLineMatches(context, verified.pairs);
  const Eigen::Matrix4d& c = verified.refinement.covariance;
  std::vector<LineMatch> kept;
  if (kept_pairs != nullptr) kept_pairs->clear();
  for (size_t i = 0; i < matches.size(); ++i) {
    if (std::find(reported.begin(), reported.end(), verified.pairs[i]) != reported.end()) {
      kept.push_back(matches[i]);
      if (kept_pairs != nullptr) kept_pairs->push_back(verified.pairs[i]);
      continue;
    }
    Eigen::Matrix<double, 2, 4> j;
    EndpointResiduals(matches[i], *context.camera, context.height, context.tilt,
                      {verified.pose, verified.refinement.focal_scale}, &j);
    const Eigen::Matrix<double, 2, 4> wj = matches[i].whitening * j;
    const Eigen::Matrix2d leverage = wj * c * wj.transpose();
    // The variance along the worst direction grows by 1 / (1 - largest eigenvalue) without it.
    if (Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(leverage, Eigen::EigenvaluesOnly)
            .eigenvalues()
            .maxCoeff() < options.max_unreported_leverage) {
      kept.push_back(matches[i]);
      if (kept_pairs != nullptr) kept_pairs->push_back(verified.pairs[i]);
    }
  }
  if (kept.size() == matches.size()) return verified.refinement;
  // Refitted under the same cost as the verification (the prior's bounds included), so the kept
  // pairs cannot slide out of the prior; the result's covariance is the image information alone.
  return RefinePose(kept, *context.camera, context.height, context.tilt,
                    {verified.pose, verified.refinement.focal_scale},
                    RefinementOptions(context, options));
}

std::vector<VerifiedPose> LeaveOneOutRivals(const VerificationContext& context,
                                            const VerificationOptions& options,
                                            const VerifiedPose& verified) {
  std::vector<VerifiedPose> rivals;
  // A pair is influential when the pose without it moves beyond the pose's own uncertainty
  // (Cook's distance: Mahalanobis shift against the chi-square quantile, 3 dof).
  const Eigen::Matrix3d c = verified.refinement.covariance.topLeftCorner<3, 3>();
  const double influential = ChiSquareQuantile(3.0, NormalQuantile(options.hypothesis_quantile));
  for (size_t i = 0; i < verified.pairs.size(); ++i) {
    Pose3Dof moved;
    // A pair that alone fixes a direction of the pose (no deleted pose) is always tried.
    if (DeletedPose(context, verified, i, &moved) && c.determinant() > 0.0) {
      const Eigen::Vector3d shift(WrapAngle(moved.heading - verified.pose.heading),
                                  moved.x - verified.pose.x, moved.y - verified.pose.y);
      if (SamePose(moved, verified.pose, options) &&
          shift.dot(c.ldlt().solve(shift)) <= influential) {
        continue;
      }
    }
    std::vector<std::pair<int, int>> others = verified.pairs;
    others.erase(others.begin() + static_cast<long>(i));
    VerificationContext without = context;
    without.excluded_pair = verified.pairs[i];
    rivals.push_back(
        Rematch(without, RefineHypothesis(context, others, {moved}, options), options));
  }
  return rivals;
}

bool RankPoses(const VerificationContext& context, const VerificationOptions& options,
               std::vector<VerifiedPose>* verified, std::string* why) {
  if (verified->empty()) {
    *why = "no consistent hypothesis";
    return false;
  }
  for (VerifiedPose& v : *verified) {
    if (v.plausible) CompleteEvidence(context, options, &v);
  }
  std::stable_sort(verified->begin(), verified->end(), BetterThan);
  if (!verified->front().plausible) {
    *why = "no plausible pose (best: " + verified->front().implausible_because + ")";
    return false;
  }
  // The best pose's rivals hidden by one of its correspondences join the comparison.
  for (VerifiedPose& rival : LeaveOneOutRivals(context, options, verified->front())) {
    if (rival.plausible) CompleteEvidence(context, options, &rival);
    verified->push_back(std::move(rival));
  }
  std::stable_sort(verified->begin(), verified->end(), BetterThan);
  return true;
}

std::vector<size_t> DistinctPoses(const std::vector<VerifiedPose>& ranked,
                                  const VerificationOptions& options) {
  std::vector<size_t> distinct = {0};
  std::vector<Pose3Dof> poses = {ranked.front().pose};
  for (size_t i = 0; i < ranked.size(); ++i) {
    const VerifiedPose& v = ranked[i];
    if (!v.plausible) break;
    if (std::any_of(poses.begin(), poses.end(),
                    [&](const Pose3Dof& d) { return SamePose(d, v.pose, options); })) {
      continue;
    }
    poses.push_back(v.pose);
    distinct.push_back(i);
  }
  return distinct;
}

bool ClearlyBest(const VerificationContext& context, const VerificationOptions& options,
                 const std::vector<size_t>& distinct, std::vector<VerifiedPose>* ranked,
                 std::string* why) {
  const VerifiedPose& best = ranked->front();
  const double score = best.evidence.Score();
  if (distinct.size() > 1 &&
      score - (*ranked)[distinct[1]].evidence.Score() < options.ambiguity_nats) {
    *why = "ambiguous: another pose explains the image almost as well";
    return false;
  }
  // An unobservable pose inside the prior (or one held at its border) is a rival explanation
  // too: when a distinct one comes within the margin, the accepted pose is not clearly the best
  // explanation of the lines.
  for (VerifiedPose& v : *ranked) {
    if (!v.unobservable || v.evidence.lines_nats < score - options.ambiguity_nats ||
        SamePose(v.pose, best.pose, options)) {
      continue;  // the edges term is not positive: lines_nats bounds the evidence
    }
    CompleteEvidence(context, options, &v);
    if (v.evidence.Score() > score - options.ambiguity_nats) {
      *why = "ambiguous: " +
             std::string(v.implausible_because == "unobservable"
                             ? "an unobservable pose"
                             : "a pose held at the prior's border") +
             " explains the image almost as well";
      return false;
    }
  }
  return true;
}

Eigen::Matrix4d AnswerCovariance(const VerificationContext& context,
                                 const VerificationOptions& options, const VerifiedPose& best,
                                 const std::vector<std::pair<int, int>>& reported,
                                 std::vector<DoubtedGroup>* groups) {
  // The answer's precision comes from the pairs it can lean on: not from an unreported pair that
  // alone fixes a direction of the pose (kept when the others leave the pose unobservable).
  VerifiedPose low_leverage = best;
  low_leverage.refinement =
      LowLeverageRefinement(context, options, best, reported, &low_leverage.pairs);
  low_leverage.pose = low_leverage.refinement.pose;
  const bool observable =
      low_leverage.refinement.position_sigma_m <= options.max_position_sigma_m &&
      low_leverage.refinement.heading_sigma_rad <= DegToRad(options.max_heading_sigma_deg);
  const VerifiedPose& base = observable ? low_leverage : best;
  // And it averages over what the unreported pairs it keeps are (true or clutter).
  return options.doubt_unreported_pairs
             ? DoubtedCovariance(context, options, base, reported, groups)
             : base.refinement.covariance;
}

}  // namespace linetrack
