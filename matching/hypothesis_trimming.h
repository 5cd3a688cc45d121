// Cleaning a refined hypothesis before guided matching: which of its pairs are kept. The
// interpretation tree's gates are looser than the verification's chi-square test, so a leaf may
// hold wrong pairs beside true ones: the consensus restart, the trimming of the largest residual
// and the per-pair outlier test (deleted residuals) remove them.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <utility>
#include <vector>

#include "matching/verification.h"

namespace linetrack {

// The consensus restart's minimal poses of two pairs and the whitened chi-square of a third pair
// at each, and the trimming's refits, memoised over the hypotheses of one localisation (sibling
// leaves of the tree share most of their pairs). Keys are (edge index, line index) pairs; values
// are exactly those computed without the memo.
struct ConsensusMemo {
  struct Entry {
    std::vector<Pose3Dof> poses;
    std::vector<std::unordered_map<uint64_t, double>> chi2;  // per pose, by PairKey of the third
  };
  struct Hash {
    size_t operator()(const std::pair<uint64_t, uint64_t>& k) const {
      return std::hash<uint64_t>()(k.first * 0x9E3779B97F4A7C15ULL ^ k.second);
    }
  };
  static uint64_t PairKey(const std::pair<int, int>& pair) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(pair.first)) << 32) |
           static_cast<uint32_t>(pair.second);
  }
  std::unordered_map<std::pair<uint64_t, uint64_t>, Entry, Hash> entries;
  // Levenberg-Marquardt refits of the trimming: by (pairs, start x, y, heading, focal scale).
  using RefitKey = std::pair<std::vector<std::pair<int, int>>, std::array<double, 4>>;
  std::map<RefitKey, PoseRefinementResult> refits;
};

// True when the hypothesis' own pairs fit its pose within the noise model (chi-square test).
bool ConsistentHypothesis(const VerifiedPose& hypothesis, const VerificationOptions& options);

// Makes a refined hypothesis consistent (the interpretation tree's gates are looser than the
// chi-square test, so a leaf may hold wrong pairs beside true ones): when it is not, restarts
// from the largest subset of its pairs agreeing with a minimal pose of two of them, then drops
// the pair with the largest whitened residual and refines again while still inconsistent; then
// drops the outlying pair (OutlyingPair) while there is one. False when fewer than three pairs
// would be left.
// `memo`, when given, is read and filled by the consensus restart and the refits.
bool TrimHypothesis(const VerificationContext& context, const VerificationOptions& options,
                    VerifiedPose* hypothesis, ConsensusMemo* memo = nullptr);

// The pair of a refined hypothesis that least fits the pose of the others: the largest
// deleted-residual chi-square r' (I - H)^-1 r (r its whitened endpoint residuals, H = W J C J' W'
// its leverage block; chi2(2) when the pair is true), when above gate_chi2; -1 when none is.
int OutlyingPair(const VerificationContext& context, const VerificationOptions& options,
                 const VerifiedPose& hypothesis);

// The pose a refined hypothesis' pairs give without pair i, to first order: pose + C J_i'
// (I - H_ii)^-1 r_i (whitened residuals r_i, Jacobian J_i, leverage H_ii = J_i C J_i'), and
// when `covariance` is given its covariance C + C J_i' (I - H_ii)^-1 J_i C (heading, x, y,
// scale). False (pose unchanged) when pair i alone fixes a direction of the pose (H_ii near the
// identity).
bool DeletedPose(const VerificationContext& context, const VerifiedPose& verified, size_t i,
                 Pose3Dof* pose, Eigen::Matrix4d* covariance = nullptr);

}  // namespace linetrack
