#include "matching/localizer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <set>

#include "matching/unreported_doubt.h"
#include "models/errors.h"

namespace linetrack {

bool LocalizerOptions::Check(std::string* why) const {
  if (!(unexplained_search_share >= 0.0 && unexplained_search_share <= 1.0)) {
    *why = "unexplained_search_share: must be in [0, 1]";
    return false;
  }
  if (!(unsearched_branches_share >= 0.0 && unsearched_branches_share <= 1.0)) {
    *why = "unsearched_branches_share: must be in [0, 1]";
    return false;
  }
  if (method == MatchMethod::kHypothesizeAndTest && !sampler) {
    *why = "method: hypothesise-and-test needs a sampler";
    return false;
  }
  return noise.Check(why) && tree.Check(why) && verification.Check(why);
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
  }
  options_.tree.fragment_offset_px = options_.noise.fragment_offset_px;
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

namespace {

// A trimmed hypothesis already verified: its pose and focal scale, and the guided-matching pair
// tests its verification cost.
struct RematchedHypothesis {
  Pose3Dof pose;
  double focal_scale = 1.0;
  long pair_tests = 0;
};

// True when the trimmed hypothesis `leaf` (pairs as those of `known`) is one already verified
// (SameRefinedPose); then adds the pair tests its verification cost to `pair_tests`.
bool AlreadyVerified(const VerifiedPose& leaf, const std::vector<RematchedHypothesis>& known,
                     long* pair_tests) {
  for (const RematchedHypothesis& k : known) {
    if (SameRefinedPose(k.pose, k.focal_scale, leaf.pose, leaf.refinement.focal_scale)) {
      *pair_tests += k.pair_tests;
      return true;
    }
  }
  return false;
}

}  // namespace

PriorRegion Localizer::Prior(const LocalizationProblem& problem) const {
  PriorRegion prior;
  prior.centre = {problem.prior.x, problem.prior.y};
  prior.radius = problem.delta_t;
  prior.heading = {problem.prior.heading - problem.delta_phi,
                   problem.prior.heading + problem.delta_phi};
  prior.height = problem.height;
  prior.focal_px = 0.5 * (camera_.px + camera_.py);
  if (area_ != nullptr) {
    prior.has_bounds = true;
    prior.bounds_min = area_->BoundsMin();
    prior.bounds_max = area_->BoundsMax();
  }
  return prior;
}

LocalizationResult Localizer::Localize(const LocalizationProblem& problem) const {
  CheckProblem(problem);
  LocalizationResult result;
  const std::vector<int> ids = CandidateEdges(problem);
  result.candidate_edges = static_cast<int>(ids.size());
  const std::vector<MatchEdge> edges = PrepareEdges(model_, ids);
  const std::vector<ObservedLine> lines = PrepareLines(
      problem.lines, camera_, problem.tilt, options_.noise, options_.tree.vertical_gate_sigmas);

  const PriorRegion prior = Prior(problem);
  VerificationContext context{&edges,      &lines, &camera_, problem.height, problem.tilt,
                              &occlusion_, &prior, area_,    options_.noise};
  std::vector<VerifiedPose> verified;
  if (options_.method == MatchMethod::kInterpretationTree) {
    // Leaves are verified as the search finds them: the pose of the leaf's correspondences
    // (Levenberg-Marquardt, trimmed to consistency), then guided matching and the evidence.
    // Branch and bound: leaves and nodes whose bound (the caps of the lines they could explain)
    // cannot come within the ambiguity margin of the best evidence found are cut; a leaf whose
    // pairs all belong to a pose already verified would converge to it and is skipped.
    InterpretationTreeStats stats;
    const VerificationOptions& vo = options_.verification;
    const LineFitModel fit_model = FitModel(context, vo);
    std::vector<double> caps;
    for (const ObservedLine& line : lines)
      caps.push_back(vo.cap_efficiency *
                     (MaxLogLikelihoodRatio(line.length_px, fit_model) - line.clutter_log_density));
    double best = -std::numeric_limits<double>::infinity();
    std::vector<std::vector<std::pair<int, int>>> verified_pairs;
    std::vector<VerifiedBasin> basins;
    long pair_tests = 0;
    context.pair_tests = &pair_tests;
    ConsensusMemo consensus_memo;
    context.consensus_memo = &consensus_memo;
    // Trimmed hypotheses already verified, with the guided-matching pair tests each cost.
    std::map<std::vector<std::pair<int, int>>, std::vector<RematchedHypothesis>> rematched;
    const LeafVisitor visit = [&](const Hypothesis& h) {
      const double bound = std::isfinite(best) ? best - vo.ambiguity_nats : 0.0;
      for (const auto& pairs : verified_pairs) {
        if (std::all_of(h.pairs.begin(), h.pairs.end(), [&](const auto& p) {
              return std::binary_search(pairs.begin(), pairs.end(), p);
            })) {
          return bound;
        }
      }
      // Mostly fitting a verified pose that explains more lines, or entirely fitting one that
      // explains as many: verified into it again.
      const int size = static_cast<int>(h.pairs.size());
      for (const VerifiedBasin& b : basins) {
        if (size > b.lines) continue;  // neither test below can hold: no pair counted
        const int fit =
            static_cast<int>(std::count_if(h.pairs.begin(), h.pairs.end(), [&](const auto& p) {
              return std::binary_search(b.fitting.begin(), b.fitting.end(), p);
            }));
        if ((size < b.lines && 2 * fit > size) || (size <= b.lines && fit == size)) {
          return bound;
        }
      }
      if (pair_tests >= vo.max_pair_tests) {
        result.budget_exhausted = true;
        return std::numeric_limits<double>::infinity();  // stops the search
      }
      ++result.hypotheses;
      VerifiedPose leaf = RefineHypothesis(context, h.pairs, h.region.Representatives(), vo);
      if (!TrimHypothesis(context, vo, &leaf) || HypothesisEvidence(context, vo, leaf) < bound) {
        return bound;
      }
      // Sibling leaves often trim to the same hypothesis (the consensus restart keeps the same
      // agreeing pairs): guided matching from it would give the same pose again, which the
      // verified poses, basins and best evidence already hold. Its share of the work budget still
      // counts.
      std::vector<std::pair<int, int>> trimmed = leaf.pairs;
      std::sort(trimmed.begin(), trimmed.end());
      std::vector<RematchedHypothesis>& known = rematched[std::move(trimmed)];
      if (AlreadyVerified(leaf, known, &pair_tests)) {
        return std::isfinite(best) ? best - vo.ambiguity_nats : 0.0;
      }
      const long tests_before = pair_tests;
      VerifiedPose v = Rematch(context, leaf, vo);
      known.push_back({leaf.pose, leaf.refinement.focal_scale, pair_tests - tests_before});
      if (v.plausible) {
        CompleteEvidence(context, vo, &v);
        best = std::max(best, v.evidence.Score());
        // Leaves that would be verified into this pose again are not verified: those whose
        // region holds it or lies within basin_sigmas of its standard deviations, and those
        // most of whose pairs fit it.
        basins.push_back({v.pose, vo.basin_sigmas * v.refinement.position_sigma_m,
                          vo.basin_sigmas * v.refinement.heading_sigma_rad,
                          static_cast<int>(v.pairs.size()), v.evidence.Score(),
                          FittingPairs(context, vo, v)});
      }
      std::vector<std::pair<int, int>> pairs = v.pairs;
      std::sort(pairs.begin(), pairs.end());
      verified_pairs.push_back(std::move(pairs));
      verified.push_back(std::move(v));
      return std::isfinite(best) ? best - vo.ambiguity_nats : 0.0;
    };
    SearchInterpretationTree(edges, lines, prior, options_.tree, caps, visit, &stats, &basins);
    result.unary_candidates = stats.unary_candidates;
    result.tree_nodes = stats.nodes;
    result.tree_checks = stats.checks;
    result.tree_completed_bound = stats.completed_bound;
    result.budget_exhausted = result.budget_exhausted || stats.budget_exhausted;
    if (result.budget_exhausted && options_.unexplained_search_share > 0.0) {
      SearchUnexplainedLines(edges, lines, prior, caps, verified, visit, &pair_tests, &result);
    }
    if (!stats.unsearched.edges.empty() && options_.unsearched_branches_share > 0.0) {
      SearchUnsearchedRootBranches(edges, lines, prior, caps, stats.unsearched, visit, &basins,
                                   &pair_tests, &result);
    }
    context.pair_tests = nullptr;
    context.consensus_memo = nullptr;
  } else {
    verified = options_.sampler(context, prior, options_.verification, &result.samples);
  }
  if (options_.method != MatchMethod::kInterpretationTree) {
    result.hypotheses = static_cast<int>(verified.size());
  }
  Decide(std::move(verified), context, edges, &result);
  return result;
}

void Localizer::SearchUnexplainedLines(const std::vector<MatchEdge>& edges,
                                       const std::vector<ObservedLine>& lines,
                                       const PriorRegion& prior, const std::vector<double>& caps,
                                       const std::vector<VerifiedPose>& verified,
                                       const LeafVisitor& visit, long* pair_tests,
                                       LocalizationResult* result) const {
  // First the lines the best pose does not explain at all; when that finds nothing better, the
  // lines it does not explain with a reported correspondence (it may hold contested true lines).
  std::vector<bool> searched;
  double searched_from = -std::numeric_limits<double>::infinity();
  for (const bool reported_only : {false, true}) {
    const VerifiedPose* top = nullptr;
    for (const VerifiedPose& v : verified) {
      if (v.plausible && (top == nullptr || v.evidence.Score() > top->evidence.Score())) top = &v;
    }
    if (top == nullptr || (reported_only && top->evidence.Score() > searched_from)) return;
    std::vector<bool> explained(lines.size(), false);
    for (const auto& pair : reported_only ? top->confident_pairs : top->pairs)
      explained[pair.second] = true;
    if (explained == searched) return;
    searched = explained;
    searched_from = top->evidence.Score();
    std::vector<ObservedLine> rest;
    std::vector<double> rest_caps;
    for (size_t l = 0; l < lines.size(); ++l) {
      if (explained[l]) continue;
      rest.push_back(lines[l]);
      rest_caps.push_back(caps[l]);
    }
    if (static_cast<int>(rest.size()) < options_.tree.min_matches) continue;
    // Leaves over `rest` are handed on with the line indices of the full list
    // (ObservedLine::index is the position in it), with a fresh verification budget. `top` may
    // dangle from here on: the visitor adds to `verified`.
    const double share = options_.unexplained_search_share;
    *pair_tests = static_cast<long>((1.0 - share) *
                                    static_cast<double>(options_.verification.max_pair_tests));
    InterpretationTreeOptions tree = options_.tree;
    tree.max_nodes = std::max(1, static_cast<int>(share * tree.max_nodes));
    tree.max_checks = std::max(1, static_cast<int>(share * tree.max_checks));
    tree.max_hypotheses = std::max(1, static_cast<int>(share * tree.max_hypotheses));
    InterpretationTreeStats stats;
    SearchInterpretationTree(
        edges, rest, prior, tree, rest_caps,
        [&](const Hypothesis& h) {
          Hypothesis full = h;
          for (auto& pair : full.pairs)
            pair.second = rest[pair.second].index;
          return visit(full);
        },
        &stats, nullptr);
    result->tree_nodes += stats.nodes;
    result->tree_checks += stats.checks;
    result->unexplained_completed_bound =
        std::max(result->unexplained_completed_bound, stats.completed_bound);
  }
}

void Localizer::SearchUnsearchedRootBranches(
    const std::vector<MatchEdge>& edges, const std::vector<ObservedLine>& lines,
    const PriorRegion& prior, const std::vector<double>& caps, const UnsearchedBranches& branches,
    const LeafVisitor& visit, const std::vector<VerifiedBasin>* basins, long* pair_tests,
    LocalizationResult* result) const {
  const double share = options_.unsearched_branches_share;
  *pair_tests =
      static_cast<long>((1.0 - share) * static_cast<double>(options_.verification.max_pair_tests));
  InterpretationTreeOptions tree = options_.tree;
  tree.max_nodes = std::max(1, static_cast<int>(share * tree.max_nodes));
  tree.max_checks = std::max(1, static_cast<int>(share * tree.max_checks));
  tree.max_hypotheses = std::max(1, static_cast<int>(share * tree.max_hypotheses));
  InterpretationTreeStats stats;
  SearchUnsearchedBranches(edges, lines, prior, tree, caps, branches, visit, &stats, basins);
  result->tree_nodes += stats.nodes;
  result->tree_checks += stats.checks;
}

void Localizer::Decide(std::vector<VerifiedPose> verified, const VerificationContext& context,
                       const std::vector<MatchEdge>& edges, LocalizationResult* out) const {
  LocalizationResult& result = *out;
  const VerificationOptions& vo = options_.verification;
  if (verified.empty()) {
    result.reason = "no consistent hypothesis";
    return;
  }
  for (VerifiedPose& v : verified) {
    if (v.plausible) CompleteEvidence(context, vo, &v);
  }
  std::stable_sort(verified.begin(), verified.end(), BetterThan);
  if (!verified.front().plausible) {
    result.reason = "no plausible pose (best: " + verified.front().implausible_because + ")";
    return;
  }
  // The best pose's rivals hidden by one of its correspondences join the comparison.
  for (VerifiedPose& rival : LeaveOneOutRivals(context, vo, verified.front())) {
    if (rival.plausible) CompleteEvidence(context, vo, &rival);
    verified.push_back(std::move(rival));
  }
  std::stable_sort(verified.begin(), verified.end(), BetterThan);
  const VerifiedPose& best = verified.front();
  // Finalists: the best pose, then the best of each distinct other pose (diagnostics).
  auto finalist = [&](const VerifiedPose& v) {
    Finalist f{v.pose, v.matched_edges, v.mean_distance_px, v.evidence, {}};
    for (const auto& [e, l] : v.pairs)
      f.matches.emplace_back(edges[e].edge_id, l);
    return f;
  };
  result.finalists.push_back(finalist(best));
  std::vector<Pose3Dof> distinct = {best.pose};
  for (const VerifiedPose& v : verified) {
    if (!v.plausible) break;
    if (std::any_of(distinct.begin(), distinct.end(),
                    [&](const Pose3Dof& d) { return SamePose(d, v.pose, vo); })) {
      continue;
    }
    distinct.push_back(v.pose);
    result.finalists.push_back(finalist(v));
  }
  result.support = best.evidence.Support();
  result.score_px = best.score_px;
  const double score = best.evidence.Score();
  if (result.finalists.size() > 1 &&
      score - result.finalists[1].evidence.Score() < vo.ambiguity_nats) {
    result.reason = "ambiguous: another pose explains the image almost as well";
    return;
  }
  // An unobservable pose inside the prior (or one held at its border) is a rival explanation
  // too: when a distinct one comes within the margin, the accepted pose is not clearly the best
  // explanation of the lines.
  for (VerifiedPose& v : verified) {
    if (!v.unobservable || v.evidence.lines_nats < score - vo.ambiguity_nats ||
        SamePose(v.pose, best.pose, vo)) {
      continue;  // the edges term is not positive: lines_nats bounds the evidence
    }
    CompleteEvidence(context, vo, &v);
    if (v.evidence.Score() > score - vo.ambiguity_nats) {
      result.reason = "ambiguous: " +
                      std::string(v.implausible_because == "unobservable"
                                      ? "an unobservable pose"
                                      : "a pose held at the prior's border") +
                      " explains the image almost as well";
      return;
    }
  }
  const double required = RequiredEvidence(context, vo, best);
  if (score < required) {
    result.reason =
        "weak evidence (" + std::to_string(score) + " of " + std::to_string(required) + " nats)";
    return;
  }
  // Only correspondences that also beat every rival line at the pose of the others are reported.
  const std::vector<std::pair<int, int>> reported = PairsBeatingRivalLines(context, vo, best);
  std::set<int> confident_edges;
  for (const auto& pair : reported)
    confident_edges.insert(pair.first);
  if (static_cast<int>(confident_edges.size()) < vo.min_confident_edges) {
    result.reason =
        "too few uncontested correspondences (" + std::to_string(confident_edges.size()) + ")";
    return;
  }
  result.found = true;
  result.pose = {best.pose.x, best.pose.y, best.pose.heading, context.height, context.tilt};
  result.cam_from_world = CamFromWorld(result.pose);
  // The answer's precision comes from the pairs it vouches for: not from an unreported pair that
  // alone fixes a direction of the pose (kept when the others leave the pose unobservable).
  VerifiedPose vouched = best;
  vouched.refinement = VouchedRefinement(context, vo, best, reported, &vouched.pairs);
  vouched.pose = vouched.refinement.pose;
  const bool observable =
      vouched.refinement.position_sigma_m <= vo.max_position_sigma_m &&
      vouched.refinement.heading_sigma_rad <= DegToRad(vo.max_heading_sigma_deg);
  const VerifiedPose& base = observable ? vouched : best;
  // And it averages over what the unreported pairs it keeps are (true or clutter).
  std::vector<DoubtedGroup> groups;
  const Eigen::Matrix4d covariance = vo.doubt_unreported_pairs
                                         ? DoubtedCovariance(context, vo, base, reported, &groups)
                                         : base.refinement.covariance;
  for (const DoubtedGroup& group : groups) {
    DoubtedMatches doubted{{}, group.probability_true};
    for (const auto& [e, l] : group.pairs)
      doubted.matches.emplace_back(edges[e].edge_id, l);
    result.doubted.push_back(std::move(doubted));
  }
  result.covariance = covariance.topLeftCorner<3, 3>();
  result.heading_sigma_rad = std::sqrt(covariance(0, 0));
  result.position_sigma_m = LargestPositionSigma(covariance.block<2, 2>(1, 1));
  for (const auto& [e, l] : reported)
    result.matches.emplace_back(edges[e].edge_id, l);
  std::sort(result.matches.begin(), result.matches.end());
}

}  // namespace linetrack
