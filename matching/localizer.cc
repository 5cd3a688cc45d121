#include "matching/localizer.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>

#include "models/errors.h"

namespace linetrack {

bool LocalizerOptions::Check(std::string* why) const {
  return noise.Check(why) && tree.Check(why) && baseline.Check(why) && verification.Check(why);
}

void CheckProblem(const LocalizationProblem& p) {
  auto finite = [](double v, const char* field) {
    if (!std::isfinite(v)) throw InputError(std::string(field) + ": not a finite number");
  };
  finite(p.prior.x, "prior x");
  finite(p.prior.y, "prior y");
  finite(p.prior.heading, "prior heading");
  finite(p.delta_t, "delta_t");
  finite(p.delta_phi, "delta_phi");
  finite(p.height, "height");
  finite(p.tilt, "tilt");
  if (p.delta_t < 0.0) throw InputError("delta_t: must be >= 0 metres");
  if (p.delta_phi <= 0.0 || p.delta_phi > kPi)
    throw InputError("delta_phi: must be in (0, 180] degrees");
  if (std::abs(p.tilt) >= 0.5 * kPi - 1e-6) throw InputError("tilt: must be in (-90, 90) degrees");
  if (p.lines.empty()) throw InputError("lines: no line segments");
  for (size_t i = 0; i < p.lines.size(); ++i) {
    const Segment2& s = p.lines[i];
    if (!s.a.allFinite() || !s.b.allFinite()) {
      throw InputError("lines[" + std::to_string(i) + "]: coordinates are not finite");
    }
    if (s.Length() < 1e-6)
      throw InputError("lines[" + std::to_string(i) + "]: zero-length segment");
  }
}

Localizer::Localizer(const WireframeModel& model, const ViewInvariantRegions* regions,
                     const NavigableArea* area, const CameraIntrinsics& camera,
                     const LocalizerOptions& options)
    : model_(model),
      regions_(regions),
      area_(area),
      camera_(camera.Undistorted()),
      options_(options),
      occlusion_(model) {
  // The focal scale is estimated with the pose, with the calibration error as its prior.
  if (options_.verification.refinement.focal_prior_sigma == 0.0) {
    options_.verification.refinement.focal_prior_sigma = options_.noise.focal_relative;
    options_.verification.refinement.prior_pixel_sigma = std::max(options_.noise.offset_px, 0.5);
  }
  std::string why;
  if (!options_.Check(&why)) throw InputError("localizer options: " + why);
  if (!camera_.Check(&why)) throw InputError("camera: " + why);
  if (camera_.width <= 0) throw InputError("camera: the image size is unknown");
}

std::vector<int> Localizer::CandidateEdges(const LocalizationProblem& problem) const {
  if (problem.candidate_edges) return *problem.candidate_edges;
  if (regions_ == nullptr || regions_->size() == 0) {
    std::vector<int> all(model_.edges().size());
    std::iota(all.begin(), all.end(), 0);
    return all;
  }
  VisibilityQuery query;
  query.centre = {problem.prior.x, problem.prior.y};
  query.radius = problem.delta_t;
  query.heading = problem.prior.heading;
  query.heading_margin = problem.delta_phi;
  query.bearing_half_width = BearingHalfWidth(camera_, problem.tilt, problem.tilt);
  return regions_->Query(query);
}

LocalizationResult Localizer::Localize(const LocalizationProblem& problem) const {
  CheckProblem(problem);
  LocalizationResult result;
  const std::vector<int> ids = CandidateEdges(problem);
  result.candidate_edges = static_cast<int>(ids.size());
  const std::vector<MatchEdge> edges = PrepareEdges(model_, ids);
  const std::vector<ObservedLine> lines = PrepareLines(
      problem.lines, camera_, problem.tilt, options_.noise, options_.tree.vertical_gate_sigmas);

  PriorRegion prior;
  prior.centre = {problem.prior.x, problem.prior.y};
  prior.radius = problem.delta_t;
  prior.heading = {problem.prior.heading - problem.delta_phi,
                   problem.prior.heading + problem.delta_phi};
  prior.height = problem.height;
  prior.focal_px = 0.5 * (camera_.px + camera_.py);
  VerificationContext context{&edges,         &lines,       &camera_,
                              problem.height, problem.tilt, &occlusion_,
                              &prior,         area_,        options_.noise.focal_relative};
  std::vector<VerifiedPose> verified;
  if (options_.method == MatchMethod::kInterpretationTree) {
    // Leaves are verified as the search finds them: the pose of the leaf's correspondences
    // first (Levenberg-Marquardt), then guided matching from it -- unless that pose is within
    // the duplicate tolerance of a leaf pose already verified, which would converge the same way.
    // Branch and bound: once a leaf of m correspondences verifies plausibly, leaves smaller than
    // m - bound_slack are pruned (the truth's leaf holds nearly all the edges the tree assigns).
    InterpretationTreeStats stats;
    int best_leaf = 0;
    std::vector<Pose3Dof> leaf_poses;  // LM poses of the leaves verified in full
    const VerificationOptions& vo = options_.verification;
    SearchInterpretationTree(
        edges, lines, prior, options_.tree,
        [&](const Hypothesis& h) {
          ++result.hypotheses;
          VerifiedPose leaf = RefineHypothesis(context, h.pairs, h.region.Representatives(), vo);
          for (const Pose3Dof& seen : leaf_poses) {
            if (std::hypot(seen.x - leaf.pose.x, seen.y - leaf.pose.y) < vo.duplicate_distance_m &&
                std::abs(WrapAngle(seen.heading - leaf.pose.heading)) <
                    DegToRad(vo.duplicate_heading_deg)) {
              return best_leaf - options_.tree.bound_slack;
            }
          }
          leaf_poses.push_back(leaf.pose);
          verified.push_back(Rematch(context, leaf, vo));
          if (verified.back().plausible) {
            best_leaf = std::max(best_leaf, static_cast<int>(h.pairs.size()));
          }
          return best_leaf - options_.tree.bound_slack;
        },
        &stats);
    result.unary_candidates = stats.unary_candidates;
    result.tree_nodes = stats.nodes;
    result.budget_exhausted = stats.budget_exhausted;
  } else {
    BaselineStats stats;
    verified = SampleAndVerify(context, prior, options_.baseline, options_.verification, &stats);
    result.samples = stats.samples;
  }
  if (options_.method != MatchMethod::kInterpretationTree) {
    result.hypotheses = static_cast<int>(verified.size());
  }
  Decide(std::move(verified), context, edges, &result);
  return result;
}

void Localizer::Decide(std::vector<VerifiedPose> verified, const VerificationContext& context,
                       const std::vector<MatchEdge>& edges, LocalizationResult* out) const {
  LocalizationResult& result = *out;
  if (verified.empty()) {
    result.reason = "no consistent hypothesis";
    return;
  }
  // Finalists: the plausible hypotheses, best first by matched edges, each distinct set of
  // correspondences once; all are scored by their evidence (with occlusion).
  std::sort(verified.begin(), verified.end(), BetterThan);
  const VerificationOptions& vo = options_.verification;
  std::vector<const VerifiedPose*> finalists;
  std::set<std::vector<std::pair<int, int>>> seen;
  for (const VerifiedPose& v : verified) {
    if (!v.plausible || static_cast<int>(finalists.size()) >= vo.finalists) break;
    std::vector<std::pair<int, int>> key = v.pairs;
    std::sort(key.begin(), key.end());
    if (seen.insert(std::move(key)).second) finalists.push_back(&v);
  }
  if (finalists.empty()) {
    const VerifiedPose& best = verified.front();
    result.reason = "no plausible pose (best: " + std::to_string(best.matched_edges) +
                    " edges, rms " + std::to_string(best.refinement.rms_px) + " px)";
    return;
  }
  std::vector<PoseEvidence> evidence;
  for (const VerifiedPose* f : finalists) {
    evidence.push_back(Evidence(context, model_, occlusion_, *f, vo));
  }
  size_t chosen = 0;
  for (size_t i = 1; i < finalists.size(); ++i) {
    if (evidence[i].Score() > evidence[chosen].Score()) chosen = i;
  }
  const VerifiedPose& chosen_pose = *finalists[chosen];
  // The correspondences reported are matched afresh at the chosen pose, so that hypotheses
  // converging to the same pose report the same matches.
  VerifiedPose rematched = Rematch(context, chosen_pose, vo);
  const VerifiedPose& best = rematched.plausible ? rematched : chosen_pose;
  auto distinct = [&](const Pose3Dof& a, const Pose3Dof& b) {
    return std::hypot(a.x - b.x, a.y - b.y) > vo.ambiguity_distance_m ||
           std::abs(WrapAngle(a.heading - b.heading)) > DegToRad(vo.ambiguity_heading_deg);
  };
  for (size_t i = 0; i < finalists.size(); ++i) {
    if (i == chosen || !distinct(finalists[i]->pose, best.pose)) continue;
    Finalist f{finalists[i]->pose,
               finalists[i]->matched_edges,
               finalists[i]->mean_distance_px,
               evidence[i],
               {}};
    for (const auto& [e, l] : finalists[i]->pairs)
      f.matches.emplace_back(edges[e].edge_id, l);
    result.finalists.push_back(std::move(f));
  }
  std::sort(
      result.finalists.begin(), result.finalists.end(),
      [](const Finalist& a, const Finalist& b) { return a.evidence.Score() > b.evidence.Score(); });
  {
    Finalist f{best.pose, best.matched_edges, best.mean_distance_px, evidence[chosen], {}};
    for (const auto& [e, l] : best.pairs)
      f.matches.emplace_back(edges[e].edge_id, l);
    result.finalists.insert(result.finalists.begin(), std::move(f));
  }
  if (result.finalists.size() > 1 &&
      result.finalists[1].evidence.Score() >= vo.ambiguity_ratio * evidence[chosen].Score()) {
    result.reason = "ambiguous: another pose explains the image almost as well";
    return;
  }
  result.support = evidence[chosen].Support();
  if (result.support < vo.min_support) {
    result.reason = "low support " + std::to_string(result.support);
    return;
  }
  std::set<int> confident_edges;
  for (const auto& pair : best.confident_pairs)
    confident_edges.insert(pair.first);
  if (static_cast<int>(confident_edges.size()) < vo.min_confident_edges) {
    result.reason =
        "too few uncontested correspondences (" + std::to_string(confident_edges.size()) + ")";
    return;
  }
  result.found = true;
  result.pose = {best.pose.x, best.pose.y, best.pose.heading, context.height, context.tilt};
  result.cam_from_world = CamFromWorld(result.pose);
  result.score_px = best.score_px;
  for (const auto& [e, l] : best.confident_pairs)
    result.matches.emplace_back(edges[e].edge_id, l);
  std::sort(result.matches.begin(), result.matches.end());
}

}  // namespace linetrack
