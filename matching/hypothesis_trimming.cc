// Cleaning a hypothesis before it is verified: the consensus restart, the trimming of residual
// outliers and the per-pair outlier test.
#include "matching/hypothesis_trimming.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "matching/quantiles.h"

namespace linetrack {

bool ConsistentHypothesis(const VerifiedPose& hypothesis, const VerificationOptions& options) {
  const int dof = 2 * static_cast<int>(hypothesis.pairs.size()) - 3;
  return hypothesis.refinement.chi2 <=
         ChiSquareQuantile(dof, NormalQuantile(options.hypothesis_quantile));
}

namespace {

// The largest subset of the hypothesis' pairs that agrees with one minimal pose (two of its
// pairs, at least one non-vertical): each pair's whitened residuals there within
// consensus_chi2. Returns the pairs and sets *pose; empty when no minimal pose exists. Reads and
// fills `memo` when given.
std::vector<std::pair<int, int>> Consensus(const VerificationContext& context,
                                           const VerificationOptions& options,
                                           const std::vector<std::pair<int, int>>& pairs,
                                           Pose3Dof* pose, ConsensusMemo* memo) {
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
      if (memo != nullptr) {
        const auto [it, inserted] = memo->entries.try_emplace(
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

// Levenberg-Marquardt on `pairs` from `start`; read from and added to `memo` when given (the
// trimming of sibling leaves refits the same pairs from the same starts).
PoseRefinementResult Refit(const VerificationContext& context, const VerificationOptions& options,
                           const std::vector<std::pair<int, int>>& pairs, const PoseAndScale& start,
                           ConsensusMemo* memo) {
  auto refine = [&] {
    return RefinePose(ToLineMatches(context, pairs), *context.camera, context.height, context.tilt,
                      start, RefinementOptions(context, options));
  };
  if (memo == nullptr) return refine();
  ConsensusMemo::RefitKey key{pairs,
                              {start.pose.x, start.pose.y, start.pose.heading, start.focal_scale}};
  const auto found = memo->refits.find(key);
  if (found != memo->refits.end()) return found->second;
  const PoseRefinementResult result = refine();
  memo->refits.emplace(std::move(key), result);
  return result;
}

// The chi-square test of a hypothesis as a whole, restored by the consensus restart and the
// trimming of the largest residual (TrimHypothesis without the per-pair test).
bool RestoreConsistency(const VerificationContext& context, const VerificationOptions& options,
                        VerifiedPose* hypothesis, ConsensusMemo* memo) {
  if (ConsistentHypothesis(*hypothesis, options)) return true;
  const std::vector<std::pair<int, int>> original = hypothesis->pairs;
  {
    // A leaf holding wrong pairs: restart from the pairs that agree with a minimal pose.
    Pose3Dof start;
    std::vector<std::pair<int, int>> agreeing =
        Consensus(context, options, hypothesis->pairs, &start, memo);
    if (agreeing.size() < 3) return false;
    hypothesis->pairs = std::move(agreeing);
    hypothesis->refinement = Refit(context, options, hypothesis->pairs, {start, 1.0}, memo);
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
    hypothesis->refinement = Refit(context, options, hypothesis->pairs,
                                   {hypothesis->pose, hypothesis->refinement.focal_scale}, memo);
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
    trial.refinement = Refit(context, options, trial.pairs,
                             {hypothesis->pose, hypothesis->refinement.focal_scale}, memo);
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

bool TrimHypothesis(const VerificationContext& context, const VerificationOptions& options,
                    VerifiedPose* hypothesis, ConsensusMemo* memo) {
  if (!RestoreConsistency(context, options, hypothesis, memo)) return false;
  // A wrong pair can hide in a consistent hypothesis by moving the pose along a weakly observed
  // direction: each pair is tested against the pose of the others.
  for (int worst = OutlyingPair(context, options, *hypothesis); worst >= 0;
       worst = OutlyingPair(context, options, *hypothesis)) {
    if (hypothesis->pairs.size() <= 3) return false;
    hypothesis->pairs.erase(hypothesis->pairs.begin() + worst);
    hypothesis->refinement = Refit(context, options, hypothesis->pairs,
                                   {hypothesis->pose, hypothesis->refinement.focal_scale}, memo);
    hypothesis->pose = hypothesis->refinement.pose;
  }
  return true;
}

}  // namespace linetrack
