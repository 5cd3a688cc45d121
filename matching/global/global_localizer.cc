#include "matching/global/global_localizer.h"

#include <algorithm>
#include <cmath>

#include "matching/pose_decision.h"
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
  return true;
}

GlobalOptions GlobalOptionsFor(const LocalizerOptions& localizer) {
  GlobalOptions options;
  options.heading.line_angle_sigma_deg = localizer.noise.angle_deg;
  options.heading.line_offset_sigma_px = localizer.noise.offset_px;
  return options;
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
      HeadingSearch s;
      s.heading = heading;
      s.heading_bound = bound;
      searches.push_back(std::move(s));
    }
  }
  return searches;
}

namespace {

// A finalist of one search: its pose, evidence and whether that search accepted it.
struct Explanation {
  Pose3Dof pose;
  double score = 0.0;  // evidence (nats)
  int search = -1;
  bool accepted = false;  // the search's own answer
};

// Every finalist of every search (those that accepted no pose included: their best may be the
// truth, too weakly seen), best first, one per distinct pose.
std::vector<Explanation> Explanations(const std::vector<HeadingSearch>& searches,
                                      const VerificationOptions& vo) {
  std::vector<Explanation> all;
  for (size_t i = 0; i < searches.size(); ++i) {
    const LocalizationResult& r = searches[i].result;
    for (size_t k = 0; k < r.finalists.size(); ++k) {
      all.push_back({r.finalists[k].pose, r.finalists[k].evidence.Score(), static_cast<int>(i),
                     r.found && k == 0});
    }
  }
  std::stable_sort(all.begin(), all.end(),
                   [](const Explanation& a, const Explanation& b) { return a.score > b.score; });
  std::vector<Explanation> distinct;
  for (const Explanation& e : all) {
    if (std::none_of(distinct.begin(), distinct.end(),
                     [&](const Explanation& d) { return SamePose(d.pose, e.pose, vo); })) {
      distinct.push_back(e);
    }
  }
  return distinct;
}

// The answer from the searches: the best explanation when a search accepted it, no distinct
// pose comes within the ambiguity margin and it observes min_support of its predicted outline;
// "ambiguous" with the rivals when a distinct pose comes within the margin; else the reason.
void Decide(const VerificationOptions& vo, double min_support, GlobalResult* out) {
  const std::vector<Explanation> explanations = Explanations(out->searches, vo);
  if (explanations.empty()) {
    out->reason = "no heading candidate's search found a plausible pose";
    return;
  }
  const Explanation& best = explanations.front();
  const LocalizationResult& best_search = out->searches[best.search].result;
  std::vector<Pose3Dof> rivals;
  for (const Explanation& e : explanations) {
    if (e.score > best.score - vo.ambiguity_nats) rivals.push_back(e.pose);
  }
  const double support =
      best_search.finalists.empty() ? 0.0 : best_search.finalists.front().evidence.Support();
  if (rivals.size() == 1 && best.accepted && support < min_support) {
    out->reason = "the best pose observes " + std::to_string(static_cast<int>(100.0 * support)) +
                  " % of its predicted outline (a partial explanation)";
    return;
  }
  if (rivals.size() == 1 && best.accepted) {
    out->found = true;
    out->best = best_search;
    return;
  }
  if (rivals.size() > 1) {
    out->ambiguous = true;
    out->rivals = rivals;
    out->reason = "ambiguous: " + std::to_string(rivals.size()) +
                  " distinct poses explain the image almost as well";
    return;
  }
  out->reason = best_search.reason;
  out->ambiguous = best_search.reason.rfind("ambiguous", 0) == 0;
  if (out->ambiguous) out->rivals = rivals;
}

}  // namespace

GlobalLocalizer::GlobalLocalizer(const Localizer& localizer, const ModelDirections& directions,
                                 const GlobalOptions& options)
    : localizer_(localizer), directions_(directions), options_(options) {
  std::string why;
  if (!options_.Check(&why)) throw InputError("global localisation options: " + why);
  if (localizer_.area() == nullptr) {
    throw InputError("global localisation needs the model's navigable area");
  }
  if (directions_.angles.empty()) {
    throw InputError("global localisation needs the model's horizontal directions");
  }
}

LocalizationProblem GlobalLocalizer::SearchProblem(const GlobalProblem& problem,
                                                   const HeadingSearch& search) const {
  LocalizationProblem local;
  local.lines = problem.lines;
  local.height = problem.height;
  local.tilt = problem.tilt;
  // The whole navigable area: the disk around its bounding box.
  const Eigen::Vector2d lo = localizer_.area()->BoundsMin(), hi = localizer_.area()->BoundsMax();
  local.prior = {0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), search.heading};
  local.delta_t = 0.5 * (hi - lo).norm();
  local.delta_phi = search.heading_bound;
  return local;
}

GlobalResult GlobalLocalizer::Localize(const GlobalProblem& problem) const {
  HeadingSearch probe;
  probe.heading_bound = DegToRad(options_.min_heading_bound_deg);
  CheckProblem(SearchProblem(problem, probe));

  GlobalResult out;
  out.headings = EstimateHeading(problem.lines, localizer_.camera(), problem.tilt, directions_,
                                 options_.heading);
  if (!out.headings.found) {
    out.reason = "no heading: " + out.headings.reason;
    return out;
  }
  out.searches = PlanHeadingSearches(out.headings, options_);
  for (HeadingSearch& s : out.searches)
    s.result = localizer_.Localize(SearchProblem(problem, s));
  Decide(localizer_.options().verification, options_.min_support, &out);
  return out;
}

}  // namespace linetrack
