#include "matching/evaluation/baseline_sampler.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "models/errors.h"

namespace linetrack {

bool BaselineOptions::Check(std::string* why) const {
  if (max_samples < 1 || !(confidence > 0.0 && confidence < 1.0)) {
    *why = "baseline: max_samples >= 1 and confidence in (0, 1)";
    return false;
  }
  return true;
}

std::vector<VerifiedPose> SampleAndVerify(const VerificationContext& context,
                                          const PriorRegion& prior, const BaselineOptions& options,
                                          const VerificationOptions& verification,
                                          BaselineStats* stats) {
  *stats = BaselineStats();
  std::vector<VerifiedPose> verified;
  const int num_edges = static_cast<int>(context.edges->size());
  const int num_lines = static_cast<int>(context.lines->size());
  if (num_edges < 2 || num_lines < 2) return verified;
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<int> pick_edge(0, num_edges - 1), pick_line(0, num_lines - 1);
  const double combos = static_cast<double>(num_edges) * num_lines;
  double needed = options.max_samples;
  int best_matches = 0;
  for (int s = 0; s < options.max_samples && s < needed; ++s) {
    ++stats->samples;
    const int e1 = pick_edge(rng), e2 = pick_edge(rng), l1 = pick_line(rng), l2 = pick_line(rng);
    if (e1 == e2 || l1 == l2) continue;
    const MatchEdge& edge1 = (*context.edges)[e1];
    const MatchEdge& edge2 = (*context.edges)[e2];
    for (const Pose3Dof& pose :
         MinimalPoses((*context.lines)[l1], edge1, (*context.lines)[l2], edge2, prior.height)) {
      // Inside the prior: heading interval and disk (the same prior the tree gets).
      const double shift =
          2.0 * kPi * std::round((prior.heading.Mid() - pose.heading) / (2.0 * kPi));
      if (pose.heading + shift < prior.heading.lo || pose.heading + shift > prior.heading.hi ||
          std::hypot(pose.x - prior.centre.x(), pose.y - prior.centre.y()) > prior.radius) {
        continue;
      }
      ++stats->poses;
      verified.push_back(VerifyHypothesis(context, {{e1, l1}, {e2, l2}}, {pose}, verification));
      const VerifiedPose& v = verified.back();
      if (v.plausible && v.matched_edges > best_matches) {
        // Adaptive stop: with m true correspondences among E x L, a drawn pair is all-true
        // with probability m (m - 1) / (E L)^2.
        best_matches = v.matched_edges;
        const double p = best_matches * (best_matches - 1.0) / (combos * combos);
        needed =
            p > 0.0 ? std::log(1.0 - options.confidence) / std::log(1.0 - p) : options.max_samples;
      }
    }
  }
  return verified;
}

HypothesisSampler BaselineSampler(const BaselineOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError("localizer options: " + why);
  return [options](const VerificationContext& context, const PriorRegion& prior,
                   const VerificationOptions& verification, int* samples) {
    BaselineStats stats;
    std::vector<VerifiedPose> verified =
        SampleAndVerify(context, prior, options, verification, &stats);
    *samples = stats.samples;
    return verified;
  };
}

}  // namespace linetrack
