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
      DistanceToLine(l, at) /
      PositionBandHalfWidth(line, p, Eigen::Vector3d(at.x(), at.y(), height), truth.heading, 1.0);
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

namespace {

// The truth of one problem followed through the matcher's stages, with the localizer's candidate
// edges and prepared lines.
class TruthDiagnoser {
 public:
  TruthDiagnoser(const Localizer& localizer, const LocalizationProblem& problem,
                 const Pose3Dof& truth)
      : localizer_(localizer),
        problem_(problem),
        truth_(truth),
        options_(localizer.options()),
        camera_(localizer.camera()),
        prior_(localizer.Prior(problem)) {
    const std::vector<int> ids = localizer.CandidateEdges(problem);
    edges_ = PrepareEdges(localizer.model(), ids);
    for (size_t i = 0; i < ids.size(); ++i)
      index_of_edge_[ids[i]] = static_cast<int>(i);
    lines_ = PrepareLines(problem.lines, camera_, problem.tilt, options_.noise,
                          options_.tree.vertical_gate_sigmas);
    gate_.sigmas = options_.tree.gate_sigmas;
    gate_.extent_slack_px = options_.tree.extent_slack_px;
    gate_.focal_px = prior_.focal_px;
  }

  // Each true correspondence through the candidate edges and the unary constraints, and the
  // counts of edges that pass; keeps the truth's hypothesis for FollowRegion.
  void CheckPairs(const std::vector<std::pair<int, int>>& truth_matches, TruthDiagnosis* out) {
    std::set<int> true_edges, candidate_edges, unary_edges;
    for (const auto& [edge_id, line_index] : truth_matches) {
      const TruthPairCheck check = CheckPair(edge_id, line_index);
      true_edges.insert(edge_id);
      if (check.candidate) candidate_edges.insert(edge_id);
      if (check.candidate && check.unary_pass) {
        unary_edges.insert(edge_id);
        // Per candidate edge index: the longest true line passing the unary constraint.
        const int e = index_of_edge_[edge_id];
        auto it = hypothesis_.find(e);
        if (it == hypothesis_.end() ||
            lines_[line_index].length_px > lines_[it->second].length_px) {
          hypothesis_[e] = line_index;
        }
      }
      out->pairs.push_back(check);
    }
    out->true_edges = static_cast<int>(true_edges.size());
    out->candidate_edges = static_cast<int>(candidate_edges.size());
    out->unary_edges = static_cast<int>(unary_edges.size());
  }

  // The truth's hypothesis (each true edge with its longest line passing the unary constraint)
  // through the feasible region, non-vertical edges first (tree order).
  void FollowRegion(TruthDiagnosis* out) const {
    std::vector<std::pair<int, int>> pairs(hypothesis_.begin(), hypothesis_.end());
    std::stable_sort(pairs.begin(), pairs.end(), [&](const auto& a, const auto& b) {
      return !edges_[a.first].vertical && edges_[b.first].vertical;
    });
    const InterpretationTreeOptions& tree = options_.tree;
    const double min_width = DegToRad(tree.heading_bin_deg);
    FeasibleRegion region =
        FeasibleRegion::FromPrior(prior_.heading, prior_.centre, prior_.radius,
                                  std::max(min_width, prior_.heading.Width() / tree.max_bins));
    out->region_consistent = true;
    for (const auto& [e, l] : pairs) {
      const bool kept =
          edges_[e].vertical
              ? AddVertical(lines_[l], edges_[e], tree.gate_sigmas, &region)
              : AddNonVertical(lines_[l], edges_[e], problem_.height, tree.gate_sigmas, &region);
      if (!kept) {
        out->region_consistent = false;
        out->region_emptied_by = edges_[e].edge_id;
        break;
      }
      region.Refine(tree.max_bins, min_width);
    }
    out->region_contains_truth = out->region_consistent && RegionHolds(region, truth_);
  }

  // All true correspondences verified as the matcher verifies a hypothesis, from the true pose.
  void VerifyTruth(const std::vector<std::pair<int, int>>& truth_matches,
                   TruthDiagnosis* out) const {
    const VerificationContext context{&edges_,         &lines_,           &camera_,
                                      problem_.height, problem_.tilt,     &localizer_.occlusion(),
                                      &prior_,         localizer_.area(), options_.noise};
    VerificationOptions vo = options_.verification;
    if (vo.refinement.focal_prior_sigma == 0.0) {
      vo.refinement.focal_prior_sigma = options_.noise.focal_relative;
    }
    std::vector<std::pair<int, int>> all_true;
    for (const auto& [edge_id, line_index] : truth_matches) {
      const auto it = index_of_edge_.find(edge_id);
      if (it != index_of_edge_.end()) all_true.emplace_back(it->second, line_index);
    }
    if (all_true.size() < 2) {
      out->implausible_because = "fewer than two true candidate pairs";
      return;
    }
    const VerifiedPose start = RefineHypothesis(context, all_true, {truth_}, vo);
    out->position_sigma_m = start.refinement.position_sigma_m;
    out->heading_sigma_deg = RadToDeg(start.refinement.heading_sigma_rad);
    const VerifiedPose verified = Rematch(context, start, vo);
    out->plausible = verified.plausible;
    out->implausible_because = verified.implausible_because;
    out->matched_edges = verified.matched_edges;
    out->rms_px = verified.refinement.rms_px;
    VerifiedPose completed = verified;
    CompleteEvidence(context, vo, &completed);
    out->evidence_score = completed.evidence.Score();
    const std::set<std::pair<int, int>> kept(verified.pairs.begin(), verified.pairs.end());
    for (TruthPairCheck& check : out->pairs) {
      const auto it = index_of_edge_.find(check.edge_id);
      if (it == index_of_edge_.end()) continue;
      const int e = it->second;
      check.guided = kept.count({e, check.line}) > 0;
      const LineMatch match{edges_[e].a, edges_[e].b, lines_[check.line].pixels};
      check.distance_px = std::sqrt(
          0.5 * EndpointResiduals(match, camera_, problem_.height, problem_.tilt, verified.pose)
                    .squaredNorm());
    }
  }

 private:
  // One true correspondence (model edge id, line index) through the candidate edges and its
  // unary constraint, with its residuals at the true pose.
  TruthPairCheck CheckPair(int edge_id, int line_index) const {
    TruthPairCheck check;
    check.edge_id = edge_id;
    check.line = line_index;
    const MatchEdge edge = PrepareEdges(localizer_.model(), {edge_id}).front();
    const ObservedLine& line = lines_.at(line_index);
    check.vertical = edge.vertical;
    check.candidate = index_of_edge_.count(edge_id) > 0;
    if (edge.vertical) {
      check.vertical_line = line.maybe_vertical;
      VerticalResiduals(line, edge, truth_, &check);
      check.unary_pass =
          line.maybe_vertical && UnaryVertical(line, edge, prior_, gate_).has_value();
    } else {
      NonVerticalResiduals(line, edge, problem_.height, truth_, &check);
      check.unary_pass = !UnaryNonVertical(line, edge, prior_, gate_).empty();
    }
    return check;
  }

  const Localizer& localizer_;
  const LocalizationProblem& problem_;
  const Pose3Dof truth_;
  const LocalizerOptions& options_;
  const CameraIntrinsics& camera_;
  std::vector<MatchEdge> edges_;
  std::map<int, int> index_of_edge_;  // model edge id -> index into edges_
  std::vector<ObservedLine> lines_;
  const PriorRegion prior_;
  Gate gate_;
  std::map<int, int> hypothesis_;  // candidate edge index -> the truth's line for it
};

}  // namespace

TruthDiagnosis DiagnoseTruth(const Localizer& localizer, const LocalizationProblem& problem,
                             const Pose3Dof& truth,
                             const std::vector<std::pair<int, int>>& truth_matches) {
  TruthDiagnosis out;
  TruthDiagnoser diagnoser(localizer, problem, truth);
  diagnoser.CheckPairs(truth_matches, &out);
  diagnoser.FollowRegion(&out);
  diagnoser.VerifyTruth(truth_matches, &out);
  return out;
}

}  // namespace linetrack
