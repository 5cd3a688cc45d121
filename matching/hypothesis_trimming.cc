// Cleaning a hypothesis before it is verified: the consensus restart, the trimming of residual
// outliers, the per-pair outlier test, the leave-one-out rivals of the decision and
// the refinement over the pairs an answer vouches for.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <Eigen/Eigenvalues>

#include "matching/verification.h"
#include "matching/verification_internal.h"

namespace linetrack {

PoseRefinementOptions RefinementOptions(const VerificationContext& context,
                                        const VerificationOptions& options) {
  PoseRefinementOptions refinement = options.refinement;
  if (context.prior == nullptr) return refinement;
  const PriorRegion& prior = *context.prior;
  refinement.bounds.active = true;
  refinement.bounds.centre = prior.centre;
  refinement.bounds.radius_m = prior.radius + options.prior_margin_m;
  refinement.bounds.heading = prior.heading.Mid();
  refinement.bounds.half_width_rad =
      0.5 * prior.heading.Width() + DegToRad(options.prior_margin_deg);
  refinement.bounds.sigmas = options.prior_margin_sigmas;
  return refinement;
}

namespace {

// The largest subset of the hypothesis' pairs that agrees with one minimal pose (two of its
// pairs, at least one non-vertical): each pair's whitened residuals there within
// consensus_chi2. Returns the pairs and sets *pose; empty when no minimal pose exists.
std::vector<std::pair<int, int>> Consensus(const VerificationContext& context,
                                           const VerificationOptions& options,
                                           const std::vector<std::pair<int, int>>& pairs,
                                           Pose3Dof* pose) {
  const std::vector<LineMatch> matches = ToLineMatches(context, pairs);
  std::vector<std::pair<int, int>> best;
  double best_chi2 = 0.0;
  std::vector<std::pair<int, int>> inliers;
  ConsensusMemo::Entry local;
  for (size_t i = 0; i < pairs.size(); ++i) {
    for (size_t j = i + 1; j < pairs.size(); ++j) {
      const auto [e1, l1] = pairs[i];
      const auto [e2, l2] = pairs[j];
      ConsensusMemo::Entry* entry = &local;
      bool fresh = true;
      if (context.consensus_memo != nullptr) {
        const auto [it, inserted] = context.consensus_memo->entries.try_emplace(
            {ConsensusMemo::PairKey(pairs[i]), ConsensusMemo::PairKey(pairs[j])});
        entry = &it->second;
        fresh = inserted;
      }
      if (fresh) {
        entry->poses = MinimalPoses((*context.lines)[l1], (*context.edges)[e1],
                                    (*context.lines)[l2], (*context.edges)[e2], context.height);
        entry->chi2.assign(entry->poses.size(), {});
      }
      for (size_t p = 0; p < entry->poses.size(); ++p) {
        const Pose3Dof& candidate = entry->poses[p];
        inliers.clear();
        double chi2 = 0.0;
        std::optional<PoseView> view;
        for (size_t k = 0; k < matches.size(); ++k) {
          // Stop when this pose can no longer beat the best one (more inliers, or as many with a
          // smaller chi-square): the result is the same.
          const size_t most = inliers.size() + (matches.size() - k);
          if (most < best.size() || (most == best.size() && chi2 >= best_chi2)) break;
          const auto [it, inserted] =
              entry->chi2[p].try_emplace(ConsensusMemo::PairKey(pairs[k]), 0.0);
          if (inserted) {
            if (!view) view = ViewOf(candidate, context.height, context.tilt);
            it->second = (matches[k].whitening *
                          EndpointResiduals(matches[k], *context.camera, *view, 1.0, nullptr))
                             .squaredNorm();
          }
          const double c = it->second;
          if (c > options.consensus_chi2) continue;
          inliers.push_back(pairs[k]);
          chi2 += c;
        }
        if (inliers.size() > best.size() || (inliers.size() == best.size() && chi2 < best_chi2)) {
          best = inliers;
          best_chi2 = chi2;
          *pose = candidate;
        }
      }
    }
  }
  return best;
}

}  // namespace

namespace {

// Levenberg-Marquardt on `pairs` from (start, scale); read from and added to the context's memo
// when it has one (the trimming of sibling leaves refits the same pairs from the same starts).
PoseRefinementResult Refit(const VerificationContext& context, const VerificationOptions& options,
                           const std::vector<std::pair<int, int>>& pairs, const Pose3Dof& start,
                           double scale) {
  auto refine = [&] {
    return RefinePose(ToLineMatches(context, pairs), *context.camera, context.height, context.tilt,
                      PoseAndScale{start, scale}, RefinementOptions(context, options));
  };
  if (context.consensus_memo == nullptr) return refine();
  ConsensusMemo::RefitKey key{pairs, {start.x, start.y, start.heading, scale}};
  const auto found = context.consensus_memo->refits.find(key);
  if (found != context.consensus_memo->refits.end()) return found->second;
  const PoseRefinementResult result = refine();
  context.consensus_memo->refits.emplace(std::move(key), result);
  return result;
}

// The chi-square test of a hypothesis as a whole, restored by the consensus restart and the
// trimming of the largest residual (TrimHypothesis without the per-pair test).
bool RestoreConsistency(const VerificationContext& context, const VerificationOptions& options,
                        VerifiedPose* hypothesis) {
  if (ConsistentHypothesis(*hypothesis, options)) return true;
  const std::vector<std::pair<int, int>> original = hypothesis->pairs;
  {
    // A leaf holding wrong pairs: restart from the pairs that agree with a minimal pose.
    Pose3Dof start;
    std::vector<std::pair<int, int>> agreeing =
        Consensus(context, options, hypothesis->pairs, &start);
    if (agreeing.size() < 3) return false;
    hypothesis->pairs = std::move(agreeing);
    hypothesis->refinement = Refit(context, options, hypothesis->pairs, start, 1.0);
    hypothesis->pose = hypothesis->refinement.pose;
  }
  while (!ConsistentHypothesis(*hypothesis, options)) {
    if (hypothesis->pairs.size() <= 3) return false;
    const std::vector<LineMatch> matches = ToLineMatches(context, hypothesis->pairs);
    size_t worst = 0;
    double worst_chi2 = -1.0;
    for (size_t i = 0; i < matches.size(); ++i) {
      const double chi2 =
          (matches[i].whitening *
           EndpointResiduals(matches[i], *context.camera, context.height, context.tilt,
                             {hypothesis->pose, hypothesis->refinement.focal_scale}, nullptr))
              .squaredNorm();
      if (chi2 > worst_chi2) {
        worst_chi2 = chi2;
        worst = i;
      }
    }
    hypothesis->pairs.erase(hypothesis->pairs.begin() + worst);
    hypothesis->refinement = Refit(context, options, hypothesis->pairs, hypothesis->pose,
                                   hypothesis->refinement.focal_scale);
    hypothesis->pose = hypothesis->refinement.pose;
  }
  // Pairs dropped on the way that fit the consistent pose are taken back (the minimal pose of the
  // consensus is rough), as long as the hypothesis stays consistent.
  for (int round = 0; round < 2; ++round) {
    VerifiedPose trial = *hypothesis;
    const std::vector<LineMatch> matches = ToLineMatches(context, original);
    for (size_t i = 0; i < original.size(); ++i) {
      if (std::find(trial.pairs.begin(), trial.pairs.end(), original[i]) != trial.pairs.end()) {
        continue;
      }
      const double chi2 =
          (matches[i].whitening *
           EndpointResiduals(matches[i], *context.camera, context.height, context.tilt,
                             {hypothesis->pose, hypothesis->refinement.focal_scale}, nullptr))
              .squaredNorm();
      if (chi2 <= options.gate_chi2) trial.pairs.push_back(original[i]);
    }
    if (trial.pairs.size() == hypothesis->pairs.size()) break;
    trial.refinement =
        Refit(context, options, trial.pairs, hypothesis->pose, hypothesis->refinement.focal_scale);
    trial.pose = trial.refinement.pose;
    if (!ConsistentHypothesis(trial, options)) break;
    *hypothesis = std::move(trial);
  }
  return true;
}

}  // namespace

int OutlyingPair(const VerificationContext& context, const VerificationOptions& options,
                 const VerifiedPose& hypothesis) {
  const std::vector<LineMatch> matches = ToLineMatches(context, hypothesis.pairs);
  // The covariance of the cost minimised (with the prior's bounds where they hold the pose).
  const Eigen::Matrix4d& c = hypothesis.refinement.bounded_covariance;
  int worst = -1;
  double worst_chi2 = options.gate_chi2;
  for (size_t i = 0; i < matches.size(); ++i) {
    Eigen::Matrix<double, 2, 4> j;
    const Eigen::Vector2d r =
        matches[i].whitening *
        EndpointResiduals(matches[i], *context.camera, context.height, context.tilt,
                          {hypothesis.pose, hypothesis.refinement.focal_scale}, &j);
    const Eigen::Matrix<double, 2, 4> wj = matches[i].whitening * j;
    const Eigen::Matrix2d complement = Eigen::Matrix2d::Identity() - wj * c * wj.transpose();
    // A leverage near 1 (the pair alone fixes a direction of the pose) cannot be tested.
    if (!(complement.determinant() > 1e-6)) continue;
    const double chi2 = r.dot(complement.inverse() * r);
    if (chi2 > worst_chi2) {
      worst_chi2 = chi2;
      worst = static_cast<int>(i);
    }
  }
  return worst;
}

bool DeletedPose(const VerificationContext& context, const VerifiedPose& verified, size_t i,
                 Pose3Dof* pose, Eigen::Matrix4d* covariance) {
  *pose = verified.pose;
  const LineMatch match = ToLineMatches(context, {verified.pairs.at(i)}).front();
  Eigen::Matrix<double, 2, 4> j;
  const Eigen::Vector2d r =
      match.whitening * EndpointResiduals(match, *context.camera, context.height, context.tilt,
                                          {verified.pose, verified.refinement.focal_scale}, &j);
  const Eigen::Matrix<double, 2, 4> wj = match.whitening * j;
  const Eigen::Matrix4d& c = verified.refinement.bounded_covariance;
  const Eigen::Matrix2d complement = Eigen::Matrix2d::Identity() - wj * c * wj.transpose();
  if (!(complement.determinant() > 1e-6)) return false;
  // Sherman-Morrison-Woodbury on the normal equations (J = d residual / d pose, whitened):
  // delta = C J_i' (I - H_ii)^-1 r_i.
  const Eigen::Matrix2d complement_inverse = complement.inverse();
  const Eigen::Vector4d delta = c * wj.transpose() * complement_inverse * r;
  pose->heading += delta(0);
  pose->x += delta(1);
  pose->y += delta(2);
  // The same identity for the covariance: (C^-1 - J_i' J_i)^-1 = C + C J_i' (I - H_ii)^-1 J_i C.
  if (covariance != nullptr) *covariance = c + c * wj.transpose() * complement_inverse * wj * c;
  return true;
}

PoseRefinementResult VouchedRefinement(const VerificationContext& context,
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

bool TrimHypothesis(const VerificationContext& context, const VerificationOptions& options,
                    VerifiedPose* hypothesis) {
  if (!RestoreConsistency(context, options, hypothesis)) return false;
  // A wrong pair can hide in a consistent hypothesis by moving the pose along a weakly observed
  // direction: each pair is tested against the pose of the others.
  for (int worst = OutlyingPair(context, options, *hypothesis); worst >= 0;
       worst = OutlyingPair(context, options, *hypothesis)) {
    if (hypothesis->pairs.size() <= 3) return false;
    hypothesis->pairs.erase(hypothesis->pairs.begin() + worst);
    hypothesis->refinement = Refit(context, options, hypothesis->pairs, hypothesis->pose,
                                   hypothesis->refinement.focal_scale);
    hypothesis->pose = hypothesis->refinement.pose;
  }
  return true;
}

}  // namespace linetrack
