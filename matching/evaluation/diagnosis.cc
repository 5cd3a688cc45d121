#include "matching/evaluation/diagnosis.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace linetrack {
namespace {

// Residuals of a non-vertical true pair at the true pose, in standard deviations.
void NonVerticalResiduals(const ObservedLine& line, const MatchEdge& edge, double height,
                          const Pose3Dof& truth, TruthPairCheck* check) {
  const Eigen::Vector3d abc = DirectionCoefficients(line.normal, edge.dir);
  const double g1 = abc.x() * std::cos(truth.heading) + abc.y() * std::sin(truth.heading) + abc.z();
  const double sigma1 =
      std::sqrt(FormVariance(line, LevelFromWorld(truth.heading) * edge.dir)) + 1e-15;
  check->first_sigmas = std::abs(g1) / sigma1;
  const Eigen::Vector2d at(truth.x, truth.y);
  const Eigen::Vector3d p = ObservedPointOnEdge(line, edge, height, truth.heading, at);
  const Eigen::Vector3d l = PositionLine(line.normal, p, height, truth.heading);
  check->second_sigmas =
      DistanceToLine(l, at) / PositionBandHalfWidth(line, p, height, truth.heading, at, 1.0);
}

void VerticalResiduals(const ObservedLine& line, const MatchEdge& edge, const Pose3Dof& truth,
                       TruthPairCheck* check) {
  check->first_sigmas =
      std::abs(line.normal.y()) / std::sqrt(std::max(line.normal_cov(1, 1), 1e-18));
  const Eigen::Vector2d to_foot = edge.foot - Eigen::Vector2d(truth.x, truth.y);
  const double bearing = std::atan2(to_foot.y(), to_foot.x());
  check->second_sigmas = std::abs(WrapAngle(bearing - (truth.heading - line.bearing))) /
                         std::max(line.bearing_sigma, 1e-12);
}

bool RegionHolds(const FeasibleRegion& region, const Pose3Dof& truth) {
  for (const HeadingBin& bin : region.bins) {
    const double h = truth.heading + 2.0 * kPi * std::round((bin.lo - truth.heading) / (2.0 * kPi));
    if (h < bin.lo - 1e-9 || h > bin.hi + 1e-9) continue;
    // Inside the convex polygon (counter-clockwise).
    bool inside = bin.positions.size() >= 3;
    const Eigen::Vector2d q(truth.x, truth.y);
    for (int i = 0; i < bin.positions.size() && inside; ++i) {
      const Eigen::Vector2d& a = bin.positions.begin()[i];
      const Eigen::Vector2d& b = bin.positions.begin()[(i + 1) % bin.positions.size()];
      inside = Cross2(b - a, q - a) >= -1e-9;
    }
    if (inside) return true;
  }
  return false;
}

}  // namespace

LocalizationProblem ProblemOf(const SyntheticScene& scene) {
  LocalizationProblem p;
  p.lines = scene.lines;
  p.prior = scene.prior;
  p.delta_t = scene.delta_t;
  p.delta_phi = scene.delta_phi;
  p.height = scene.height;
  p.tilt = scene.tilt;
  return p;
}

TruthDiagnosis DiagnoseTruth(const Localizer& localizer, const LocalizationProblem& problem,
                             const Pose3Dof& truth,
                             const std::vector<std::pair<int, int>>& truth_matches) {
  const LocalizerOptions& options = localizer.options();
  const CameraIntrinsics& camera = localizer.camera();
  TruthDiagnosis out;
  const std::vector<int> ids = localizer.CandidateEdges(problem);
  const std::vector<MatchEdge> edges = PrepareEdges(localizer.model(), ids);
  std::map<int, int> index_of_edge;
  for (size_t i = 0; i < ids.size(); ++i)
    index_of_edge[ids[i]] = static_cast<int>(i);
  const std::vector<ObservedLine> lines = PrepareLines(
      problem.lines, camera, problem.tilt, options.noise, options.tree.vertical_gate_sigmas);
  const HeadingInterval prior_heading{problem.prior.heading - problem.delta_phi,
                                      problem.prior.heading + problem.delta_phi};
  const Eigen::Vector2d centre(problem.prior.x, problem.prior.y);
  Gate gate;
  gate.sigmas = options.tree.gate_sigmas;
  gate.extent_slack_px = options.tree.extent_slack_px;
  gate.focal_px = 0.5 * (camera.px + camera.py);

  std::set<int> true_edges, candidate_edges, unary_edges;
  // Per candidate edge index: the longest true line passing the unary constraint.
  std::map<int, int> hypothesis;
  for (const auto& [edge_id, line_index] : truth_matches) {
    TruthPairCheck check;
    check.edge_id = edge_id;
    check.line = line_index;
    true_edges.insert(edge_id);
    const MatchEdge edge = PrepareEdges(localizer.model(), {edge_id}).front();
    const ObservedLine& line = lines.at(line_index);
    check.vertical = edge.vertical;
    check.candidate = index_of_edge.count(edge_id) > 0;
    if (edge.vertical) {
      check.vertical_line = line.maybe_vertical;
      VerticalResiduals(line, edge, truth, &check);
      check.unary_pass =
          line.maybe_vertical &&
          UnaryVertical(line, edge, problem.height, prior_heading, centre, problem.delta_t, gate)
              .has_value();
    } else {
      NonVerticalResiduals(line, edge, problem.height, truth, &check);
      check.unary_pass = !UnaryNonVertical(line, edge, problem.height, prior_heading, centre,
                                           problem.delta_t, gate)
                              .empty();
    }
    if (check.candidate) candidate_edges.insert(edge_id);
    if (check.candidate && check.unary_pass) {
      unary_edges.insert(edge_id);
      const int e = index_of_edge[edge_id];
      auto it = hypothesis.find(e);
      if (it == hypothesis.end() || line.length_px > lines[it->second].length_px) {
        hypothesis[e] = line_index;
      }
    }
    out.pairs.push_back(check);
  }
  out.true_edges = static_cast<int>(true_edges.size());
  out.candidate_edges = static_cast<int>(candidate_edges.size());
  out.unary_edges = static_cast<int>(unary_edges.size());

  // The truth's hypothesis through the feasible region, non-vertical edges first (tree order).
  std::vector<std::pair<int, int>> pairs(hypothesis.begin(), hypothesis.end());
  std::stable_sort(pairs.begin(), pairs.end(), [&](const auto& a, const auto& b) {
    return !edges[a.first].vertical && edges[b.first].vertical;
  });
  const InterpretationTreeOptions& tree = options.tree;
  const double min_width = DegToRad(tree.heading_bin_deg);
  FeasibleRegion region =
      FeasibleRegion::FromPrior(prior_heading, centre, problem.delta_t,
                                std::max(min_width, prior_heading.Width() / tree.max_bins));
  out.region_consistent = true;
  for (const auto& [e, l] : pairs) {
    const bool kept = edges[e].vertical ? AddVertical(lines[l], edges[e], tree.gate_sigmas, &region)
                                        : AddNonVertical(lines[l], edges[e], problem.height,
                                                         tree.gate_sigmas, &region);
    if (!kept) {
      out.region_consistent = false;
      out.region_emptied_by = edges[e].edge_id;
      break;
    }
    region.Refine(tree.max_bins, min_width);
  }
  out.region_contains_truth = out.region_consistent && RegionHolds(region, truth);

  // The truth verified from the true pose.
  PriorRegion prior;
  prior.centre = centre;
  prior.radius = problem.delta_t;
  prior.heading = prior_heading;
  prior.height = problem.height;
  prior.focal_px = gate.focal_px;
  VerificationContext context{&edges,         &lines,           &camera,
                              problem.height, problem.tilt,     &localizer.occlusion(),
                              &prior,         localizer.area(), options.noise};
  VerificationOptions vo = options.verification;
  if (vo.refinement.focal_prior_sigma == 0.0) {
    vo.refinement.focal_prior_sigma = options.noise.focal_relative;
  }
  std::vector<std::pair<int, int>> all_true;
  for (const auto& [edge_id, line_index] : truth_matches) {
    if (index_of_edge.count(edge_id)) all_true.emplace_back(index_of_edge[edge_id], line_index);
  }
  if (all_true.size() >= 2) {
    const VerifiedPose start = RefineHypothesis(context, all_true, {truth}, vo);
    out.position_sigma_m = start.refinement.position_sigma_m;
    out.heading_sigma_deg = RadToDeg(start.refinement.heading_sigma_rad);
    const VerifiedPose verified = Rematch(context, start, vo);
    out.plausible = verified.plausible;
    out.implausible_because = verified.implausible_because;
    out.matched_edges = verified.matched_edges;
    out.rms_px = verified.refinement.rms_px;
    VerifiedPose completed = verified;
    CompleteEvidence(context, vo, &completed);
    out.evidence_score = completed.evidence.Score();
    const std::set<std::pair<int, int>> kept(verified.pairs.begin(), verified.pairs.end());
    for (TruthPairCheck& check : out.pairs) {
      if (!index_of_edge.count(check.edge_id)) continue;
      const int e = index_of_edge[check.edge_id];
      check.guided = kept.count({e, check.line}) > 0;
      const std::vector<LineMatch> match = {{edges[e].a, edges[e].b, lines[check.line].pixels}};
      check.distance_px = std::sqrt(
          0.5 * EndpointResiduals(match[0], camera, problem.height, problem.tilt, verified.pose)
                    .squaredNorm());
    }
  } else {
    out.implausible_because = "fewer than two true candidate pairs";
  }
  return out;
}

}  // namespace linetrack
