#include "matching/global/global_localizer.h"

#include <algorithm>
#include <cmath>

#include "matching/global/global_decision.h"
#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack {

bool GlobalOptions::Check(std::string* why) const {
  if (!heading.Check(why)) return false;
  if (max_heading_hypotheses < 1) {
    *why = "max_heading_hypotheses must be at least 1";
    return false;
  }
  if (!(min_support_share >= 0.0 && min_support_share <= 1.0)) {
    *why = "min_support_share must be in [0, 1]";
    return false;
  }
  if (!(heading_sigmas > 0.0) || !(min_heading_bound_deg > 0.0) ||
      !(max_heading_bound_deg >= min_heading_bound_deg) || !(max_heading_bound_deg < 180.0)) {
    *why =
        "heading bounds: heading_sigmas > 0, 0 < min_heading_bound_deg <= "
        "max_heading_bound_deg < 180";
    return false;
  }
  if (!(min_support >= 0.0 && min_support <= 1.0)) {
    *why = "min_support must be in [0, 1]";
    return false;
  }
  if (!(near_m >= 0.0) || !(near_deg >= 0.0)) {
    *why = "near_m and near_deg must be >= 0";
    return false;
  }
  if (!(verify_budget_share > 0.0 && verify_budget_share <= 1.0)) {
    *why = "verify_budget_share must be in (0, 1]";
    return false;
  }
  if (!(verify_delta_t_m > 0.0) || !(verify_delta_phi_deg > 0.0) || max_verified_peaks < 1) {
    *why = "verify_delta_t_m, verify_delta_phi_deg and max_verified_peaks must be positive";
    return false;
  }
  return vote.Check(why);
}

GlobalOptions GlobalOptionsFor(const LocalizerOptions& localizer) {
  GlobalOptions options;
  options.heading.line_angle_sigma_deg = localizer.noise.angle_deg;
  options.heading.line_offset_sigma_px = localizer.noise.offset_px;
  return options;
}

LocalizerOptions VerifierOptions(const LocalizerOptions& localizer, const GlobalOptions& options) {
  LocalizerOptions out = localizer;
  const double k = options.verify_budget_share;
  const auto scaled = [k](auto budget) {
    return std::max<decltype(budget)>(1, static_cast<decltype(budget)>(k * budget));
  };
  out.tree.max_nodes = scaled(out.tree.max_nodes);
  out.tree.max_checks = scaled(out.tree.max_checks);
  out.tree.max_hypotheses = scaled(out.tree.max_hypotheses);
  out.verification.max_pair_tests = scaled(out.verification.max_pair_tests);
  out.max_budget_scale = 1.0;  // the verifications' budgets are the global mode's own
  return out;
}

std::vector<HeadingSearch> PlanHeadingSearches(const HeadingCandidates& candidates,
                                               const GlobalOptions& options) {
  std::vector<HeadingSearch> searches;
  if (!candidates.found || candidates.hypotheses.empty()) return searches;
  const int best_support = candidates.hypotheses.front().support;
  const int count =
      std::min(options.max_heading_hypotheses, static_cast<int>(candidates.hypotheses.size()));
  for (int i = 0; i < count; ++i) {
    const HeadingHypothesis& h = candidates.hypotheses[i];
    if (i > 0 && h.support < options.min_support_share * best_support) break;
    const double bound = std::clamp(options.heading_sigmas * h.heading_sigma,
                                    DegToRad(options.min_heading_bound_deg),
                                    DegToRad(options.max_heading_bound_deg));
    for (double heading : h.headings) {
      searches.push_back({heading, bound});
    }
  }
  return searches;
}

namespace {

// The localizer's navigable area; throws InputError when it has none.
const NavigableArea& AreaOf(const Localizer& localizer) {
  if (localizer.area() == nullptr) {
    throw InputError("global localisation needs the model's navigable area");
  }
  return *localizer.area();
}

// The vote's options with the camera's focal length, checked with the others.
PositionVoteOptions VoteOptions(const GlobalOptions& options, const Localizer& localizer) {
  std::string why;
  if (!options.Check(&why)) throw InputError("global localisation options: " + why);
  PositionVoteOptions vote = options.vote;
  vote.tolerance.focal_px = 0.5 * (localizer.camera().px + localizer.camera().py);
  return vote;
}

}  // namespace

GlobalLocalizer::GlobalLocalizer(const Localizer& localizer, const ModelDirections& directions,
                                 const GlobalOptions& options)
    : localizer_(localizer),
      verifier_(localizer.model(), nullptr, localizer.area(), localizer.camera(),
                VerifierOptions(localizer.options(), options)),
      directions_(directions),
      options_(options),
      vote_(localizer.model(), AreaOf(localizer), VoteOptions(options, localizer)) {
  if (directions_.angles.empty()) {
    throw InputError("global localisation needs the model's horizontal directions");
  }
}

LocalizationProblem GlobalLocalizer::PeakProblem(const GlobalProblem& problem,
                                                 const PositionPeak& peak) const {
  LocalizationProblem local;
  local.lines = problem.lines;
  local.height = problem.height;
  local.tilt = problem.tilt;
  local.prior = {peak.position.x(), peak.position.y(), peak.heading};
  local.delta_t = options_.verify_delta_t_m;
  local.delta_phi = DegToRad(options_.verify_delta_phi_deg);
  local.candidate_edges = localizer_.CandidateEdges(local);
  return local;
}

GlobalResult GlobalLocalizer::Localize(const GlobalProblem& problem) const {
  CheckProblem(PeakProblem(problem, PositionPeak()));

  GlobalResult out;
  out.headings = EstimateHeading(problem.lines, localizer_.camera(), problem.tilt, directions_,
                                 options_.heading);
  if (!out.headings.found) {
    out.reason = "no heading: " + out.headings.reason;
    return out;
  }
  out.searches = PlanHeadingSearches(out.headings, options_);
  const std::vector<ObservedLine> lines =
      PrepareLines(problem.lines, localizer_.camera(), problem.tilt, localizer_.options().noise,
                   localizer_.options().tree.vertical_gate_sigmas);
  // Every search's peaks, the best max_verified_peaks of them (by votes) verified.
  std::vector<PeakVerification> peaks;
  for (size_t i = 0; i < out.searches.size(); ++i) {
    const HeadingSearch& s = out.searches[i];
    for (const PositionPeak& peak : vote_.Peaks(lines, problem.height, s.heading, s.heading_bound))
      peaks.push_back({static_cast<int>(i), peak, {}});
  }
  std::stable_sort(peaks.begin(), peaks.end(),
                   [](const PeakVerification& a, const PeakVerification& b) {
                     return a.peak.votes > b.peak.votes;
                   });
  if (static_cast<int>(peaks.size()) > options_.max_verified_peaks)
    peaks.resize(options_.max_verified_peaks);
  for (PeakVerification& v : peaks)
    v.result = verifier_.Localize(PeakProblem(problem, v.peak));
  out.verifications = std::move(peaks);
  DecideGlobal(localizer_.options().verification, options_, &out);
  return out;
}

}  // namespace linetrack
