#include "matching/reported_pairs.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "matching/edge_candidates.h"
#include "matching/hypothesis_trimming.h"

namespace linetrack {

namespace {

// The pair's own fit beyond the gates (they only save work): its line alone against every edge,
// gates open; empty when the edge is not in view, or hidden, there.
std::vector<Candidate> FitBeyondGates(const VerificationContext& context,
                                      const VerificationOptions& options,
                                      const std::vector<EdgeImage>& images,
                                      const CandidateQuery& query,
                                      const std::pair<int, int>& pair) {
  const auto [edge, line] = pair;
  LineFitModel ungated = FitModel(context, options);
  ungated.gate_chi2 = ungated.extent_sigmas = std::numeric_limits<double>::infinity();
  const std::vector<ObservedLine> alone = {(*context.lines)[line]};
  VerificationContext single = context;
  single.lines = &alone;
  single.excluded_pair = {-1, -1};
  std::vector<Candidate> beyond;
  for (Candidate& c : Candidates(single, images, ungated, query)) {
    if (c.edge != edge) continue;
    c.line = line;  // its index among all lines
    beyond.push_back(c);
  }
  return beyond;
}

}  // namespace

PairExplanations ExplainPair(const VerificationContext& context, const VerificationOptions& options,
                             const PoseAndScale& at, const Eigen::Matrix4d& covariance,
                             const std::pair<int, int>& pair, const ExplainFrom& from) {
  const auto [edge, line] = pair;
  const std::vector<EdgeImage> images =
      from.seen ? ProjectEdgesSeenFrom(context, at.pose, at.focal_scale, from.seen->pose,
                                       from.seen->focal_scale)
                : ProjectEdges(context, at.pose, at.focal_scale);
  CandidateQuery query;
  query.at = at;
  query.covariance = covariance;
  query.seen = from.seen;
  query.any_ratio = true;
  const std::vector<Candidate> fits =
      Candidates(context, images, FitModel(context, options), query);
  PairExplanations out;
  auto fit_of = [&](int e, int l) {
    return std::find_if(fits.begin(), fits.end(),
                        [&](const Candidate& c) { return c.edge == e && c.line == l; });
  };
  const auto found = fit_of(edge, line);
  const Candidate* own = found != fits.end() ? &*found : nullptr;
  std::vector<Candidate> beyond;
  if (own == nullptr && from.beyond_gates) {
    beyond = FitBeyondGates(context, options, images, query, pair);
    if (!beyond.empty()) own = &beyond.front();
  }
  if (own == nullptr) return out;  // not in view, or hidden, at that pose
  out.own = own->fit.log_likelihood_ratio;
  const double overlap_tolerance = 3.0 * context.noise.offset_px;
  // Two lines can both be images of one edge: fragments that do not overlap, on one line.
  auto fragments_of_one = [&](const Candidate& a, const Candidate& b) {
    const Segment2& pa = (*context.lines)[a.line].pixels;
    const Segment2& pb = (*context.lines)[b.line].pixels;
    const bool longer = pa.Length() > pb.Length();
    return !SpansOverlap(a.fit, b.fit, overlap_tolerance) &&
           FragmentChiSquare(longer ? pa : pb, longer ? pb : pa,
                             context.noise.fragment_offset_px) <= options.gate_chi2;
  };
  for (const Candidate& c : fits) {
    if (c.line == line && c.edge != edge) {
      out.rivals.push_back(c.fit.log_likelihood_ratio);
    }
    if (c.edge != edge || c.line == line) continue;
    if (fragments_of_one(*own, c)) {
      out.fragments = out.fragments || c.fit.log_likelihood_ratio > 0.0;
    } else {
      double displaced = 0.0;  // the ratio of the pair that explains the rival line, if any
      if (from.interpretation != nullptr) {
        for (const auto& [e, l] : *from.interpretation) {
          if (l != c.line || e == edge) continue;
          const auto other = fit_of(e, l);
          if (other != fits.end()) displaced += other->fit.log_likelihood_ratio;
        }
      }
      out.rivals.push_back(c.fit.log_likelihood_ratio - displaced);
    }
  }
  return out;
}

std::vector<std::pair<int, int>> PairsBeatingRivalLines(const VerificationContext& context,
                                                        const VerificationOptions& options,
                                                        const VerifiedPose& verified) {
  std::vector<std::pair<int, int>> reported;
  for (size_t i = 0; i < verified.pairs.size(); ++i) {
    if (!std::binary_search(verified.confident_pairs.begin(), verified.confident_pairs.end(),
                            verified.pairs[i])) {
      continue;
    }
    // The pose of the other pairs: the pair's line must not confirm itself. When the pair
    // alone fixes a direction of the pose, its own pose is all there is.
    Pose3Dof pose;
    Eigen::Matrix4d covariance;
    if (!DeletedPose(context, verified, i, &pose, &covariance)) {
      pose = verified.pose;
      covariance = verified.refinement.covariance;
    }
    const PairExplanations explained = ExplainPair(
        context, options, {pose, verified.refinement.focal_scale}, covariance, verified.pairs[i]);
    // Outside the gates at the pose of the others, or not likelier than clutter there.
    if (!(explained.own > 0.0)) continue;
    // Other explanations at that pose: another edge for the line; another line for the edge
    // that would be its image instead (over the same stretch, or off the line of this one); and,
    // when the edge has other lines there (this one would be a further fragment beside them),
    // clutter: the line must stand without pulling the pose toward itself.
    double rival = explained.fragments ? 0.0 : -std::numeric_limits<double>::infinity();
    for (const double r : explained.rivals) {
      if (r > 0.0) rival = std::max(rival, r);  // the rivals likelier than clutter
    }
    if (explained.own - rival >= options.report_nats) reported.push_back(verified.pairs[i]);
  }
  std::sort(reported.begin(), reported.end());
  return reported;
}

}  // namespace linetrack
