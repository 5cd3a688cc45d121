#include "matching/localizer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <set>

#include "matching/hypothesis_trimming.h"
#include "matching/pose_decision.h"
#include "matching/reported_pairs.h"
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
  if (!(budget_reference_edges > 0.0) || !(max_budget_scale >= 1.0 && max_budget_scale <= 100.0)) {
    *why = "budget_reference_edges must be positive and max_budget_scale in [1, 100]";
    return false;
  }
  if (method == MatchMethod::kHypothesizeAndTest && !sampler) {
    *why = "method: hypothesise-and-test needs a sampler";
    return false;
  }
  return noise.Check(why) && tree.Check(why) && verification.Check(why);
}

LocalizerOptions BudgetsForCandidates(LocalizerOptions options, int candidate_edges) {
  const double scale =
      std::clamp(candidate_edges / options.budget_reference_edges, 1.0, options.max_budget_scale);
  if (scale == 1.0) return options;
  const auto scaled = [scale](auto budget) {
    return static_cast<decltype(budget)>(std::round(scale * static_cast<double>(budget)));
  };
  options.tree.max_nodes = scaled(options.tree.max_nodes);
  options.tree.max_checks = scaled(options.tree.max_checks);
  options.tree.max_hypotheses = scaled(options.tree.max_hypotheses);
  options.verification.max_pair_tests = scaled(options.verification.max_pair_tests);
  return options;
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
  finite(p.roll, "roll");
  if (p.delta_t < 0.0) throw InputError("delta_t: must be >= 0 metres");
  if (p.delta_phi <= 0.0 || p.delta_phi > kPi)
    throw InputError("delta_phi: must be in (0, 180] degrees");
  if (std::abs(p.tilt) >= 0.5 * kPi - 1e-6) throw InputError("tilt: must be in (-90, 90) degrees");
  if (std::abs(p.roll) > kPi) throw InputError("roll: must be in [-180, 180] degrees");
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
  return regions_->Query(VisibilityQueryOf(problem, camera_));
}

VisibilityQuery VisibilityQueryOf(const LocalizationProblem& problem,
                                  const CameraIntrinsics& camera) {
  VisibilityQuery query;
  query.centre = {problem.prior.x, problem.prior.y};
  query.radius = problem.delta_t;
  query.heading = problem.prior.heading;
  query.heading_margin = problem.delta_phi;
  query.bearing_half_width = BearingHalfWidth(camera, problem.tilt, problem.tilt, problem.roll);
  query.camera_z = problem.height;
  return query;
}

std::vector<Segment2> UnrolledLines(const std::vector<Segment2>& lines,
                                    const CameraIntrinsics& camera, double roll) {
  auto unroll = [&](const Eigen::Vector2d& pixel) {
    const Eigen::Vector2d m = UnrollImagePoint(camera.Ray(pixel).head<2>(), roll);
    return Eigen::Vector2d(camera.u0 + camera.px * m.x(), camera.v0 + camera.py * m.y());
  };
  std::vector<Segment2> out;
  out.reserve(lines.size());
  for (const Segment2& s : lines)
    out.push_back({unroll(s.a), unroll(s.b)});
  return out;
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

std::vector<std::pair<int, int>> Sorted(std::vector<std::pair<int, int>> pairs) {
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

// The tree's leaves verified as the search finds them: the pose of the leaf's correspondences
// (Levenberg-Marquardt, trimmed to consistency), then guided matching and the evidence. The
// bound handed back to the search is the best evidence found less the ambiguity margin; a leaf
// that a verified pose already covers is not verified again.
class LeafVerifier {
 public:
  LeafVerifier(const VerificationContext& context, const VerificationOptions& options)
      : context_(context), options_(options) {}

  // The search's leaf visitor: verifies `h` unless covered; returns the bound to continue with
  // (infinite once the pair-test budget is spent: the search stops).
  double Visit(const Hypothesis& h) {
    if (Covered(h)) return Bound();
    if (stats_.pair_tests >= options_.max_pair_tests) {
      budget_exhausted_ = true;
      return std::numeric_limits<double>::infinity();
    }
    ++hypotheses_;
    VerifiedPose leaf = RefineHypothesis(context_, h.pairs, h.region.Representatives(), options_);
    if (!TrimHypothesis(context_, options_, &leaf, &memo_) ||
        HypothesisEvidence(context_, options_, leaf) < Bound()) {
      return Bound();
    }
    // Sibling leaves often trim to the same hypothesis (the consensus restart keeps the same
    // agreeing pairs): guided matching from it would give the same pose again, which the
    // verified poses, neighbourhoods and best evidence already hold. Its share of the work budget
    // still counts.
    std::vector<RematchedHypothesis>& known = rematched_[Sorted(leaf.pairs)];
    if (AlreadyVerified(leaf, known, &stats_.pair_tests)) return Bound();
    const long tests_before = stats_.pair_tests;
    VerifiedPose v = Rematch(context_, leaf, options_, &stats_);
    known.push_back({leaf.pose, leaf.refinement.focal_scale, stats_.pair_tests - tests_before});
    Record(std::move(v));
    return Bound();
  }

  // A fresh share of the pair-test budget for a further search: the count restarts at
  // (1 - share) of the budget.
  void GiveBudgetShare(double share) {
    stats_.pair_tests =
        static_cast<long>((1.0 - share) * static_cast<double>(options_.max_pair_tests));
  }

  const std::vector<VerifiedPose>& verified() const { return verified_; }
  std::vector<VerifiedPose> TakeVerified() { return std::move(verified_); }
  const std::vector<VerifiedNeighbourhood>* neighbourhoods() const { return &neighbourhoods_; }
  int hypotheses() const { return hypotheses_; }
  bool budget_exhausted() const { return budget_exhausted_; }

 private:
  double Bound() const { return std::isfinite(best_) ? best_ - options_.ambiguity_nats : 0.0; }

  // True when verifying `h` would give a verified pose again: its pairs all belong to one, or it
  // mostly fits a verified pose that explains more lines, or entirely fits one that explains as
  // many.
  bool Covered(const Hypothesis& h) const {
    for (const auto& pairs : verified_pairs_) {
      if (std::all_of(h.pairs.begin(), h.pairs.end(), [&](const auto& p) {
            return std::binary_search(pairs.begin(), pairs.end(), p);
          })) {
        return true;
      }
    }
    const int size = static_cast<int>(h.pairs.size());
    for (const VerifiedNeighbourhood& b : neighbourhoods_) {
      if (size > b.lines) continue;  // neither test below can hold: no pair counted
      const int fit =
          static_cast<int>(std::count_if(h.pairs.begin(), h.pairs.end(), [&](const auto& p) {
            return std::binary_search(b.consensus.begin(), b.consensus.end(), p);
          }));
      if ((size < b.lines && 2 * fit > size) || (size <= b.lines && fit == size)) return true;
    }
    return false;
  }

  // Keeps a verified leaf. Leaves that would be verified into a plausible pose again are not
  // verified: those whose region holds it or lies within neighbourhood_sigmas of its standard
  // deviations, and those most of whose pairs fit it.
  void Record(VerifiedPose v) {
    if (v.plausible) {
      CompleteEvidence(context_, options_, &v);
      best_ = std::max(best_, v.evidence.Score());
      neighbourhoods_.push_back({v.pose,
                                 options_.neighbourhood_sigmas * v.refinement.position_sigma_m,
                                 options_.neighbourhood_sigmas * v.refinement.heading_sigma_rad,
                                 static_cast<int>(v.pairs.size()), v.evidence.Score(),
                                 ConsensusSet(context_, options_, v)});
    }
    verified_pairs_.push_back(Sorted(v.pairs));
    verified_.push_back(std::move(v));
  }

  const VerificationContext& context_;
  const VerificationOptions& options_;
  std::vector<VerifiedPose> verified_;
  std::vector<std::vector<std::pair<int, int>>> verified_pairs_;  // each sorted
  std::vector<VerifiedNeighbourhood> neighbourhoods_;
  double best_ = -std::numeric_limits<double>::infinity();
  VerificationStats stats_;
  ConsensusMemo memo_;
  // Trimmed hypotheses already verified, with the guided-matching pair tests each cost.
  std::map<std::vector<std::pair<int, int>>, std::vector<RematchedHypothesis>> rematched_;
  int hypotheses_ = 0;
  bool budget_exhausted_ = false;
};

// Each line's cap for the tree's bound: cap_efficiency times the largest log-likelihood ratio
// against clutter it can reach (MaxLogLikelihoodRatio).
std::vector<double> LineCaps(const VerificationContext& context,
                             const VerificationOptions& options) {
  const LineFitModel fit_model = FitModel(context, options);
  std::vector<double> caps;
  for (const ObservedLine& line : *context.lines) {
    caps.push_back(options.cap_efficiency *
                   (MaxLogLikelihoodRatio(line.length_px, fit_model) - line.clutter_log_density));
  }
  return caps;
}

// The tree options with `share` of each of their budgets (nodes, checks, leaves; at least one).
InterpretationTreeOptions WithBudgetShare(InterpretationTreeOptions tree, double share) {
  tree.max_nodes = std::max(1, static_cast<int>(share * tree.max_nodes));
  tree.max_checks = std::max(1, static_cast<int>(share * tree.max_checks));
  tree.max_hypotheses = std::max(1, static_cast<int>(share * tree.max_hypotheses));
  return tree;
}

// The match of a verified pose for the result: (model edge id, line index).
Finalist FinalistOf(const VerifiedPose& v, const std::vector<MatchEdge>& edges) {
  Finalist f{v.pose, v.matched_edges, v.mean_distance_px, v.evidence, {}};
  for (const auto& [e, l] : v.pairs)
    f.matches.emplace_back(edges[e].edge_id, l);
  return f;
}

// An exhausted search may have missed the pose that explains the lines its best pose leaves
// unexplained (a wrong pose borrowing a few true lines hides the truth from the bound): the tree
// is searched again over those lines alone, with fresh budgets (unexplained_search_share), its
// leaves verified against all lines; when that finds nothing better, over the lines the best
// pose does not explain with a reported correspondence (it may hold contested true lines).
void SearchUnexplainedLines(const VerificationContext& context, const LocalizerOptions& options,
                            const std::vector<double>& caps, LeafVerifier* leaves,
                            LocalizationResult* result) {
  const std::vector<ObservedLine>& lines = *context.lines;
  std::vector<bool> searched;
  double searched_from = -std::numeric_limits<double>::infinity();
  for (const bool reported_only : {false, true}) {
    const VerifiedPose* top = nullptr;
    for (const VerifiedPose& v : leaves->verified()) {
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
    if (static_cast<int>(rest.size()) < options.tree.min_matches) continue;
    // Leaves over `rest` are handed on with the line indices of the full list
    // (ObservedLine::index is the position in it), with a fresh verification budget. `top` may
    // dangle from here on: the visitor adds to the verified poses.
    const double share = options.unexplained_search_share;
    leaves->GiveBudgetShare(share);
    InterpretationTreeStats stats;
    SearchInterpretationTree(
        {context.edges, &rest, context.prior, &rest_caps}, WithBudgetShare(options.tree, share),
        [&](const Hypothesis& h) {
          Hypothesis full = h;
          for (auto& pair : full.pairs)
            pair.second = rest[pair.second].index;
          return leaves->Visit(full);
        },
        &stats, nullptr);
    result->tree_nodes += stats.nodes;
    result->tree_checks += stats.checks;
    result->unexplained_completed_bound =
        std::max(result->unexplained_completed_bound, stats.completed_bound);
  }
}

// Depth first, the first root branch can take the whole budget while the root's other branches
// have the same bound: the branches `branches` the exhausted main search did not reach are
// searched with unsearched_branches_share of its budgets (a fresh share of the pair tests).
void SearchUnsearchedRootBranches(const VerificationContext& context,
                                  const LocalizerOptions& options, const std::vector<double>& caps,
                                  const UnsearchedBranches& branches, LeafVerifier* leaves,
                                  LocalizationResult* result) {
  const double share = options.unsearched_branches_share;
  leaves->GiveBudgetShare(share);
  InterpretationTreeStats stats;
  SearchUnsearchedBranches(
      {context.edges, context.lines, context.prior, &caps}, WithBudgetShare(options.tree, share),
      branches, [leaves](const Hypothesis& h) { return leaves->Visit(h); }, &stats,
      leaves->neighbourhoods());
  result->tree_nodes += stats.nodes;
  result->tree_checks += stats.checks;
}

// The interpretation tree searched as a branch and bound on the evidence, its leaves verified as
// they are found: nodes and leaves whose bound (the caps of the lines they could explain) cannot
// come within the ambiguity margin of the best evidence found are cut. Then, after an exhausted
// budget, the searches over unexplained lines and over unsearched root branches.
std::vector<VerifiedPose> SearchTree(const VerificationContext& context,
                                     const LocalizerOptions& options, LocalizationResult* result) {
  const std::vector<double> caps = LineCaps(context, options.verification);
  LeafVerifier leaves(context, options.verification);
  InterpretationTreeStats stats;
  SearchInterpretationTree(
      {context.edges, context.lines, context.prior, &caps}, options.tree,
      [&leaves](const Hypothesis& h) { return leaves.Visit(h); }, &stats, leaves.neighbourhoods());
  result->unary_candidates = stats.unary_candidates;
  result->tree_nodes = stats.nodes;
  result->tree_checks = stats.checks;
  result->tree_completed_bound = stats.completed_bound;
  if ((leaves.budget_exhausted() || stats.budget_exhausted) &&
      options.unexplained_search_share > 0.0) {
    SearchUnexplainedLines(context, options, caps, &leaves, result);
  }
  if (!stats.unsearched.edges.empty() && options.unsearched_branches_share > 0.0) {
    SearchUnsearchedRootBranches(context, options, caps, stats.unsearched, &leaves, result);
  }
  result->hypotheses = leaves.hypotheses();
  result->budget_exhausted = leaves.budget_exhausted() || stats.budget_exhausted;
  return leaves.TakeVerified();
}

// Picks the answer among the verified poses (pose_decision.h: ranking with the leave-one-out
// rivals, ambiguity, the evidence needed, the report) and fills `result`: the finalists, and
// when a pose is accepted, its reported correspondences and covariance.
void Decide(std::vector<VerifiedPose> verified, const VerificationContext& context,
            const VerificationOptions& options, LocalizationResult* result) {
  const std::vector<MatchEdge>& edges = *context.edges;
  if (!RankPoses(context, options, &verified, &result->reason)) return;
  const VerifiedPose& best = verified.front();
  const std::vector<size_t> distinct = DistinctPoses(verified, options);
  for (const size_t i : distinct)
    result->finalists.push_back(FinalistOf(verified[i], edges));
  result->support = best.evidence.Support();
  result->score_px = best.score_px;
  if (!ClearlyBest(context, options, distinct, &verified, &result->reason)) return;
  const double score = best.evidence.Score();
  const double required = RequiredEvidence(context, options, best);
  if (score < required) {
    result->reason =
        "weak evidence (" + std::to_string(score) + " of " + std::to_string(required) + " nats)";
    return;
  }
  // Only correspondences that also beat every rival line at the pose of the others are reported.
  const std::vector<std::pair<int, int>> reported = PairsBeatingRivalLines(context, options, best);
  std::set<int> confident_edges;
  for (const auto& pair : reported)
    confident_edges.insert(pair.first);
  if (static_cast<int>(confident_edges.size()) < options.min_confident_edges) {
    result->reason =
        "too few uncontested correspondences (" + std::to_string(confident_edges.size()) + ")";
    return;
  }
  result->found = true;
  result->pose = {best.pose.x, best.pose.y, best.pose.heading, context.height, context.tilt};
  result->cam_from_world = CamFromWorld(result->pose);
  std::vector<DoubtedGroup> groups;
  const Eigen::Matrix4d covariance = AnswerCovariance(context, options, best, reported, &groups);
  for (const DoubtedGroup& group : groups) {
    DoubtedMatches doubted{{}, group.probability_true};
    for (const auto& [e, l] : group.pairs)
      doubted.matches.emplace_back(edges[e].edge_id, l);
    result->doubted.push_back(std::move(doubted));
  }
  result->covariance = covariance.topLeftCorner<3, 3>();
  result->heading_sigma_rad = std::sqrt(covariance(0, 0));
  result->position_sigma_m = LargestPositionSigma(covariance.block<2, 2>(1, 1));
  for (const auto& [e, l] : reported)
    result->matches.emplace_back(edges[e].edge_id, l);
  std::sort(result->matches.begin(), result->matches.end());
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
  if (ids.empty()) {
    result.reason = "no candidate edge: " +
                    (regions_ != nullptr && !problem.candidate_edges
                         ? regions_->ExplainEmptyQuery(VisibilityQueryOf(problem, camera_))
                         : std::string(problem.candidate_edges ? "the given list is empty"
                                                               : "the model has no edges"));
    return result;
  }
  const std::vector<MatchEdge> edges = PrepareEdges(model_, ids);
  // A rolled camera's lines are matched as the unrolled camera sees them; only the frustum of
  // what the image shows stays the rolled camera's (VerificationContext::roll).
  const std::vector<ObservedLine> lines = PrepareLines(
      problem.roll == 0.0 ? problem.lines : UnrolledLines(problem.lines, camera_, problem.roll),
      camera_, problem.tilt, options_.noise, options_.tree.vertical_gate_sigmas);
  const PriorRegion prior = Prior(problem);
  VerificationContext context{&edges,      &lines, &camera_, problem.height, problem.tilt,
                              &occlusion_, &prior, area_,    options_.noise};
  context.roll = problem.roll;
  std::vector<VerifiedPose> verified;
  if (options_.method == MatchMethod::kInterpretationTree) {
    verified =
        SearchTree(context, BudgetsForCandidates(options_, static_cast<int>(ids.size())), &result);
  } else {
    verified = options_.sampler(context, prior, options_.verification, &result.samples);
    result.hypotheses = static_cast<int>(verified.size());
  }
  Decide(std::move(verified), context, options_.verification, &result);
  if (result.found && problem.roll != 0.0) {
    result.pose.roll = problem.roll;
    result.cam_from_world = CamFromWorld(result.pose);
  }
  return result;
}

}  // namespace linetrack
