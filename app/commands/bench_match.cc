// `linetrack bench match`: the paper's Table 3 on the bundled hall (synthetic scenes of section
// 4.1), for the interpretation tree and for the hypothesise-and-test baseline, side by side.
#include <spdlog/spdlog.h>

#include <map>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <set>
#include <sstream>

#include "app/commands.h"
#include "app/match_outcome.h"
#include "app/model_loading.h"
#include "matching/evaluation/baseline_sampler.h"
#include "matching/evaluation/diagnosis.h"
#include "matching/global/global_localizer.h"
#include "matching/heading/model_directions.h"
#include "matching/localizer.h"
#include "models/errors.h"
#include "models/statistics.h"
#include "models/synth/synthetic_scenes.h"
#include "models/text_format.h"

namespace linetrack::app {
namespace {

struct Series {
  std::string name;
  double delta_t = 0.0;    // metres
  double delta_phi = 0.0;  // degrees
  // The paper's Table 3 for this prior (out of 430): correct, no answer, wrong but accurate,
  // wrong; negative when the paper has no such series.
  int paper[4] = {-1, -1, -1, -1};
  // No prior: the scenes' priors are ignored and the global mode localises (docs/global.md).
  bool global = false;
};

struct BenchMatchOptions {
  std::string model_path = "models/hall.cao";
  int count = 430;
  uint64_t seed = 1;
  std::vector<std::string> series = {"qi1", "qi2", "qi3", "wide"};
  bool baseline = true;
  int baseline_samples = 200000;
  int clutter = 0;           // clutter lines per scene (0: the paper's 5 to 12)
  int parallel_clutter = 0;  // near-parallel unmodelled lines per scene (synth's option)
  std::string out_path;
  std::string diagnose_path;  // JSON lines: every scene the tree does not answer correctly
  bool verbose = false;       // also the developer's table: the doubted groups' posterior
  std::vector<int> only;      // when not empty: run these scene indices only (debugging)
};

Series SeriesByName(const std::string& name) {
  if (name == "qi1") return {"QI1 (0.30 m, 10 deg)", 0.30, 10.0, {421, 5, 4, 0}};
  if (name == "qi2") return {"QI2 (0.50 m, 15 deg)", 0.50, 15.0, {418, 5, 7, 0}};
  if (name == "qi3") return {"QI3 (0.75 m, 20 deg)", 0.75, 20.0, {415, 5, 7, 3}};
  if (name == "wide") return {"wide (2.00 m, 45 deg)", 2.00, 45.0, {-1, -1, -1, -1}};
  if (name == "global") return {"global (no prior)", 0.30, 10.0, {-1, -1, -1, -1}, true};
  throw InputError("--series: unknown series '" + name + "' (qi1, qi2, qi3, wide, global)");
}

// Outcome counts and figures of one matcher on one series.
struct Tally {
  int correct = 0, none = 0, wrong_accurate = 0, wrong = 0;
  int correct_beyond_tolerance = 0;  // correct by their own confidence region only
  std::vector<double> hypotheses, times_ms, position_error_m, heading_error_deg;

  int Total() const { return correct + none + wrong_accurate + wrong; }
};

using Outcome = MatchOutcome;

// How far the answer is from the truth (app/match_outcome.h).
PoseErrors AnswerErrors(const SyntheticScene& scene, const LocalizationResult& result) {
  return ErrorsOf(result.pose.Planar(), result.covariance, scene.truth.Planar());
}

Outcome Judge(const SyntheticScene& scene, const LocalizationResult& result,
              const PoseErrors& errors) {
  return JudgeMatch(result.found, ReportedMatchesTrue(scene.matches, result.matches), errors);
}

Outcome Score(const SyntheticScene& scene, const LocalizationResult& result, double ms,
              Tally* tally) {
  tally->hypotheses.push_back(result.hypotheses);
  tally->times_ms.push_back(ms);
  const PoseErrors errors = AnswerErrors(scene, result);
  const Outcome outcome = Judge(scene, result, errors);
  switch (outcome) {
    case Outcome::kNone:
      ++tally->none;
      break;
    case Outcome::kWrongAccurate:
      ++tally->wrong_accurate;
      break;
    case Outcome::kWrong:
      ++tally->wrong;
      break;
    case Outcome::kCorrect:
      ++tally->correct;
      if (!errors.WithinTolerance()) ++tally->correct_beyond_tolerance;
      tally->position_error_m.push_back(errors.position_m);
      tally->heading_error_deg.push_back(errors.heading_deg);
      break;
  }
  return outcome;
}

// The first stage at which the truth is lost (see matching/evaluation/diagnosis.h).
std::string Classify(const TruthDiagnosis& d, const LocalizationResult& result) {
  if (!d.plausible && d.implausible_because == "unobservable") return "uninformative truth";
  if (d.candidate_edges < d.true_edges) return "true edge not a candidate";
  if (d.unary_edges < d.candidate_edges) return "true pair cut by a unary constraint";
  if (!d.region_consistent) return "truth's region emptied";
  if (!d.region_contains_truth) return "truth's region misses the true pose";
  if (!d.plausible) return "truth implausible: " + d.implausible_because;
  if (result.budget_exhausted) return "search budget exhausted";
  if (result.found) return "truth outranked";
  const std::string& r = result.reason;
  return "truth plausible, no answer: " + r.substr(0, r.find_first_of("(0123456789"));
}

nlohmann::ordered_json DiagnosisJson(const SyntheticScene& scene, const LocalizationResult& result,
                                     Outcome outcome, const TruthDiagnosis& d,
                                     const std::string& category, const WireframeModel& model) {
  auto name = [&model](int edge) { return model.edges().at(static_cast<size_t>(edge)).name; };
  nlohmann::ordered_json pairs = nlohmann::ordered_json::array();
  for (const TruthPairCheck& p : d.pairs) {
    pairs.push_back({{"edge", p.edge_id},
                     {"name", name(p.edge_id)},
                     {"line", p.line},
                     {"vertical", p.vertical},
                     {"candidate", p.candidate},
                     {"unary", p.unary_pass},
                     {"sigmas", {p.first_sigmas, p.second_sigmas}},
                     {"distance_px", p.distance_px},
                     {"guided", p.guided}});
  }
  const std::set<std::pair<int, int>> truth(scene.matches.begin(), scene.matches.end());
  nlohmann::ordered_json wrong = nlohmann::ordered_json::array();
  nlohmann::ordered_json wrong_names = nlohmann::ordered_json::array();
  for (const auto& m : result.matches) {
    if (truth.count(m)) continue;
    wrong.push_back({m.first, m.second});
    wrong_names.push_back(name(m.first));
  }
  int pose_false_pairs = 0;  // pairs of the accepted pose's interpretation, reported or not
  if (!result.finalists.empty()) {
    for (const auto& m : result.finalists.front().matches)
      pose_false_pairs += truth.count(m) ? 0 : 1;
  }
  const PoseErrors errors = AnswerErrors(scene, result);
  nlohmann::ordered_json finalists = nlohmann::ordered_json::array();
  for (const Finalist& f : result.finalists) {
    finalists.push_back(
        {f.pose.x, f.pose.y, RadToDeg(f.pose.heading), f.evidence.Score(), f.matched_edges});
  }
  return {{"scene", scene.index},
          {"outcome", MatchOutcomeName(outcome)},
          {"category", category},
          {"reason", result.reason},
          {"hypotheses", result.hypotheses},
          {"budget_exhausted", result.budget_exhausted},
          {"tree_nodes", result.tree_nodes},
          {"tree_checks", result.tree_checks},
          {"tree_completed_bound", result.tree_completed_bound},
          {"unexplained_completed_bound", result.unexplained_completed_bound},
          {"pose_error", {errors.position_m, errors.heading_deg}},
          {"wrong_matches", wrong},
          {"wrong_match_names", wrong_names},
          {"pose_false_pairs", pose_false_pairs},
          {"truth_mahalanobis2", errors.mahalanobis2},
          {"true_edges", d.true_edges},
          {"candidate_edges", d.candidate_edges},
          {"unary_edges", d.unary_edges},
          {"region_consistent", d.region_consistent},
          {"region_emptied_by", d.region_emptied_by},
          {"region_contains_truth", d.region_contains_truth},
          {"plausible", d.plausible},
          {"implausible_because", d.implausible_because},
          {"truth_matched_edges", d.matched_edges},
          {"truth_rms_px", d.rms_px},
          {"truth_evidence", d.evidence_score},
          {"chosen_evidence",
           result.finalists.empty() ? 0.0 : result.finalists.front().evidence.Score()},
          {"observability", {d.position_sigma_m, d.heading_sigma_deg}},
          {"truth_pose", {scene.truth.x, scene.truth.y, RadToDeg(scene.truth.heading)}},
          {"finalists", finalists},
          {"pairs", pairs}};
}

// A correct answer whose search budget ran out: its evidence against the bound of the tree's
// last completed pass (the leaves it did not visit lie below it).
nlohmann::ordered_json BudgetJson(const SyntheticScene& scene, const LocalizationResult& result,
                                  const std::string& series) {
  return {{"scene", scene.index},
          {"outcome", MatchOutcomeName(MatchOutcome::kCorrect)},
          {"budget_exhausted", true},
          {"tree_nodes", result.tree_nodes},
          {"tree_checks", result.tree_checks},
          {"tree_completed_bound", result.tree_completed_bound},
          {"unexplained_completed_bound", result.unexplained_completed_bound},
          {"chosen_evidence",
           result.finalists.empty() ? 0.0 : result.finalists.front().evidence.Score()},
          {"series", series}};
}

// Calibration of the doubted groups' posterior against the scenes' truth (a group is true when
// all its pairs are): per bin of p, the groups and how many are true.
struct DoubtCalibration {
  static constexpr double kEdges[] = {0.0, 1e-9, 0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 0.999};
  static constexpr int kBins = 10;
  int groups[kBins] = {}, true_groups[kBins] = {};
  double sum_p[kBins] = {};
  double summed_doubt = 0.0;
  int loose_correct = 0;  // correct answers whose sigmas exceed the observability limits

  void Add(const SyntheticScene& scene, const LocalizationResult& result, Outcome outcome,
           const VerificationOptions& limits) {
    if (outcome == Outcome::kCorrect &&
        (result.position_sigma_m > limits.max_position_sigma_m ||
         result.heading_sigma_rad > DegToRad(limits.max_heading_sigma_deg))) {
      ++loose_correct;
    }
    const std::set<std::pair<int, int>> truth(scene.matches.begin(), scene.matches.end());
    for (const DoubtedMatches& g : result.doubted) {
      const double p = g.probability_true;
      int bin = kBins - 1;
      while (bin > 0 && p < kEdges[bin])
        --bin;
      ++groups[bin];
      sum_p[bin] += p;
      summed_doubt += 1.0 - p;
      const bool all_true = std::all_of(g.matches.begin(), g.matches.end(),
                                        [&](const auto& m) { return truth.count(m) > 0; });
      true_groups[bin] += all_true ? 1 : 0;
    }
  }

  std::string Table() const {
    std::ostringstream out;
    int total = 0, false_groups = 0;
    out << "\nPosterior of the doubted unreported groups against the truth (all series):\n\n"
        << "| p_G | groups | share true | mean p_G |\n| --- | --- | --- | --- |\n";
    for (int b = 0; b < kBins; ++b) {
      total += groups[b];
      false_groups += groups[b] - true_groups[b];
      const std::string range =
          b == 0 ? "0"
                 : (b + 1 < kBins ? std::to_string(kEdges[b]).substr(0, 5) + "-" +
                                        std::to_string(kEdges[b + 1]).substr(0, 5)
                                  : ">= 0.999");
      out << std::fixed << "| " << range << " | " << groups[b] << " | " << std::setprecision(3)
          << (groups[b] > 0 ? static_cast<double>(true_groups[b]) / groups[b] : 0.0) << " | "
          << (groups[b] > 0 ? sum_p[b] / groups[b] : 0.0) << " |\n";
    }
    out << "\nGroups " << total << ", false " << false_groups << ", summed doubt "
        << std::setprecision(1) << summed_doubt << "; correct answers with sigmas beyond the "
        << "observability limits: " << loose_correct << ".\n";
    return out.str();
  }
};

std::string Row(const std::string& matcher, const Tally& t) {
  std::ostringstream row;
  const double n = std::max(1, t.Total());
  row << std::fixed << "| " << matcher << " | " << t.correct << " (" << std::setprecision(1)
      << 100.0 * t.correct / n << " %) | " << t.none << " | " << t.wrong_accurate << " | "
      << t.wrong << " | " << std::setprecision(0) << QuantileNearestRank(t.hypotheses, 0.5) << " / "
      << QuantileNearestRank(t.hypotheses, 1.0) << " | " << std::setprecision(2)
      << QuantileNearestRank(t.times_ms, 0.5) << " / " << QuantileNearestRank(t.times_ms, 0.99)
      << " | " << std::setprecision(3) << QuantileNearestRank(t.position_error_m, 0.5) << " m, "
      << std::setprecision(2) << QuantileNearestRank(t.heading_error_deg, 0.5) << " deg |";
  return row.str();
}

// The heading vote's hypotheses for --diagnose: [heading_deg, sigma_deg, support, rms_sigmas].
nlohmann::ordered_json HeadingHypothesesJson(const HeadingCandidates& headings) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const HeadingHypothesis& h : headings.hypotheses)
    out.push_back({RadToDeg(h.heading), RadToDeg(h.heading_sigma), h.support, h.rms_sigmas});
  return out;
}

// One scene of the global series for --diagnose: the truth verified by a peak's search centred on
// the true pose (its evidence, as the matcher would score it) against every verified peak's
// finalists, and how far the truth's heading is from the nearest search's.
nlohmann::ordered_json GlobalDiagnosisJson(const GlobalLocalizer& global, const Localizer& tree,
                                           const SyntheticScene& scene, const GlobalResult& r,
                                           Outcome outcome) {
  PositionPeak at_truth;
  at_truth.position = {scene.truth.x, scene.truth.y};
  at_truth.heading = scene.truth.heading;
  const TruthDiagnosis d =
      DiagnoseTruth(tree, global.PeakProblem({scene.lines, scene.height, scene.tilt}, at_truth),
                    scene.truth.Planar(), scene.matches);
  double nearest_deg = 180.0;
  nlohmann::ordered_json searches = nlohmann::ordered_json::array();
  for (const HeadingSearch& s : r.searches) {
    nearest_deg =
        std::min(nearest_deg, std::abs(RadToDeg(WrapAngle(s.heading - scene.truth.heading))));
  }
  for (const PeakVerification& v : r.verifications) {
    nlohmann::ordered_json finalists = nlohmann::ordered_json::array();
    for (const Finalist& f : v.result.finalists) {
      std::set<int> lines;
      for (const auto& m : f.matches)
        lines.insert(m.second);
      finalists.push_back({f.pose.x, f.pose.y, RadToDeg(WrapAngle(f.pose.heading)),
                           f.evidence.Score(), f.matched_edges, f.evidence.Support(), lines.size(),
                           f.evidence.lines_nats, f.evidence.edges_nats});
    }
    searches.push_back({{"heading_deg", RadToDeg(WrapAngle(r.searches[v.search].heading))},
                        {"bound_deg", RadToDeg(r.searches[v.search].heading_bound)},
                        {"peak",
                         {v.peak.position.x(), v.peak.position.y(),
                          RadToDeg(WrapAngle(v.peak.heading)), v.peak.votes}},
                        {"found", v.result.found},
                        {"reason", v.result.reason},
                        {"finalists", finalists}});
  }
  return {{"scene", scene.index},
          {"outcome", MatchOutcomeName(outcome)},
          {"ambiguous", r.ambiguous},
          {"reason", r.reason},
          {"truth_pose", {scene.truth.x, scene.truth.y, RadToDeg(WrapAngle(scene.truth.heading))}},
          {"truth_heading_off_deg", nearest_deg},
          {"heading_hypotheses", HeadingHypothesesJson(r.headings)},
          {"truth_plausible", d.plausible},
          {"truth_implausible_because", d.implausible_because},
          {"truth_matched_edges", d.matched_edges},
          {"truth_evidence", d.evidence_score},
          {"lines", scene.lines.size()},
          {"searches", searches}};
}

// The global mode on a series' scenes, their priors ignored (scenes not in `only`, when given,
// skipped): the tally and, in *ambiguous, the unanswered scenes answered "ambiguous"; each
// scene's diagnosis appended to `diagnosis` when given.
Tally RunGlobalSeries(const Localizer& tree, const ModelDirections& directions,
                      const std::vector<SyntheticScene>& scenes, const std::vector<int>& only,
                      int* ambiguous, std::ostringstream* diagnosis) {
  const GlobalLocalizer global(tree, directions, GlobalOptionsFor(tree.options()));
  Tally tally;
  for (const SyntheticScene& scene : scenes) {
    if (!only.empty() && std::find(only.begin(), only.end(), scene.index) == only.end()) continue;
    const auto start = std::chrono::steady_clock::now();
    const GlobalResult r = global.Localize({scene.lines, scene.height, scene.tilt});
    const double ms = MillisecondsSince(start);
    LocalizationResult shown = r.found ? r.best : LocalizationResult();
    shown.hypotheses = 0;
    for (const PeakVerification& v : r.verifications)
      shown.hypotheses += v.result.hypotheses;
    const Outcome outcome = Score(scene, shown, ms, &tally);
    *ambiguous += r.ambiguous ? 1 : 0;
    if (diagnosis != nullptr) {
      nlohmann::ordered_json j = GlobalDiagnosisJson(global, tree, scene, r, outcome);
      j["ms"] = ms;
      *diagnosis << j.dump() << "\n";
    }
  }
  return tally;
}

// The table row of the global series, and its note (correct by the confidence region only,
// ambiguous answers) appended to *notes.
std::string GlobalRow(const Localizer& tree, const ModelDirections& directions,
                      const std::vector<SyntheticScene>& scenes, const std::vector<int>& only,
                      const std::string& name, std::ostringstream* notes,
                      std::ostringstream* diagnosis) {
  int ambiguous = 0;
  const Tally t = RunGlobalSeries(tree, directions, scenes, only, &ambiguous, diagnosis);
  *notes << (notes->tellp() > 0 ? "; " : "") << name << ": " << t.correct_beyond_tolerance
         << " (no answer: " << ambiguous << " ambiguous)";
  return "| " + name + " " + Row("heading + tree", t) + "\n";
}

// The set-up line and the head of the table.
std::string TableHeader(const BenchMatchOptions& opt) {
  std::ostringstream table;
  table << "Synthetic scenes of the paper's section 4.1 on " << opt.model_path << " (" << opt.count
        << " per series, seed " << opt.seed
        << (opt.clutter > 0 ? ", " + std::to_string(opt.clutter) + " clutter lines per scene" : "")
        << (opt.parallel_clutter > 0
                ? ", " + std::to_string(opt.parallel_clutter) + " near-parallel clutter lines"
                : "")
        << "); times per localisation on this machine, one thread.\n\n"
        << "| prior | matcher | correct | no answer | wrong but accurate | wrong | "
           "hypotheses verified (median / max) | time ms (median / p99) | pose error of "
           "correct answers (median) |\n"
        << "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  return table.str();
}

// The scenes of one series.
SyntheticSceneOptions SceneOptions(const BenchMatchOptions& opt, const Series& s) {
  SyntheticSceneOptions scene_options;
  scene_options.seed = opt.seed;
  scene_options.count = opt.count;
  scene_options.delta_t = s.delta_t;
  scene_options.delta_phi = DegToRad(s.delta_phi);
  if (opt.clutter > 0) scene_options.min_clutter = scene_options.max_clutter = opt.clutter;
  scene_options.parallel_clutter = opt.parallel_clutter;
  return scene_options;
}

int RunBenchMatch(const BenchMatchOptions& opt) {
  const WireframeModel model = LoadModel(opt.model_path);
  const NavigableArea area = NavigableArea::FromModel(model);
  const ViewInvariantRegions regions = ViewInvariantRegions::Build(model, area);
  const ModelDirections directions = DominantDirections(model);
  std::vector<Series> series;
  for (const std::string& name : opt.series)
    series.push_back(SeriesByName(name));

  std::unique_ptr<std::ostringstream> diagnosis;
  if (!opt.diagnose_path.empty()) diagnosis = std::make_unique<std::ostringstream>();
  std::ostringstream table;
  table << TableHeader(opt);
  std::ostringstream beyond;  // correct answers accurate only by their own confidence region
  DoubtCalibration calibration;
  for (const Series& s : series) {
    const SyntheticSceneOptions scene_options = SceneOptions(opt, s);
    spdlog::info("{}: generating {} scenes", s.name, opt.count);
    const std::vector<SyntheticScene> scenes = GenerateScenes(model, area, scene_options);

    LocalizerOptions tree_options;
    LocalizerOptions baseline_options;
    baseline_options.method = MatchMethod::kHypothesizeAndTest;
    BaselineOptions baseline_sampling;
    baseline_sampling.max_samples = opt.baseline_samples;
    baseline_options.sampler = BaselineSampler(baseline_sampling);
    const Localizer tree(model, &regions, &area, scene_options.camera, tree_options);
    if (s.global) {
      table << GlobalRow(tree, directions, scenes, opt.only, s.name, &beyond, diagnosis.get());
      continue;
    }
    const Localizer baseline(model, &regions, &area, scene_options.camera, baseline_options);
    Tally tree_tally, baseline_tally;
    std::map<std::string, int> categories;
    for (size_t i = 0; i < scenes.size(); ++i) {
      const SyntheticScene& scene = scenes[i];
      if (!opt.only.empty() &&
          std::find(opt.only.begin(), opt.only.end(), scene.index) == opt.only.end()) {
        continue;
      }
      const LocalizationProblem problem = ProblemOf(scene);
      for (int m = 0; m < (opt.baseline ? 2 : 1); ++m) {
        const auto start = std::chrono::steady_clock::now();
        const LocalizationResult result = (m == 0 ? tree : baseline).Localize(problem);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        const Outcome outcome = Score(scene, result, ms, m == 0 ? &tree_tally : &baseline_tally);
        if (m == 0) calibration.Add(scene, result, outcome, tree_options.verification);
        if (m == 0 && diagnosis && outcome != Outcome::kCorrect) {
          const TruthDiagnosis d =
              DiagnoseTruth(tree, problem, scene.truth.Planar(), scene.matches);
          const std::string category = Classify(d, result);
          ++categories[category];
          nlohmann::ordered_json j = DiagnosisJson(scene, result, outcome, d, category, model);
          j["series"] = s.name;
          *diagnosis << j.dump() << "\n";
        } else if (m == 0 && diagnosis && result.budget_exhausted) {
          // Correct answers after an exhausted search: what the budget left unexplored.
          *diagnosis << BudgetJson(scene, result, s.name).dump() << "\n";
        }
      }
      if ((i + 1) % 50 == 0) spdlog::info("{}: {}/{} scenes", s.name, i + 1, scenes.size());
    }
    table << "| " << s.name << " " << Row("tree", tree_tally) << "\n";
    if (opt.baseline) table << "| " << s.name << " " << Row("baseline", baseline_tally) << "\n";
    beyond << (beyond.tellp() > 0 ? "; " : "") << s.name << ": tree "
           << tree_tally.correct_beyond_tolerance;
    if (opt.baseline) beyond << ", baseline " << baseline_tally.correct_beyond_tolerance;
    for (const auto& [category, count] : categories) {
      spdlog::info("{}: {} scene(s): {}", s.name, count, category);
    }
    if (s.paper[0] >= 0) {
      table << "| " << s.name << " | paper (RAS 2005, Table 3) | " << s.paper[0] << " ("
            << std::fixed << std::setprecision(1) << 100.0 * s.paper[0] / 430.0 << " %) | "
            << s.paper[1] << " | " << s.paper[2] << " | " << s.paper[3]
            << " | 24-391 (real images) | - | - |\n";
    }
  }
  table << "\nCorrect: every reported correspondence true and the pose within "
        << kAccuratePositionM << " m and " << kAccurateHeadingDeg
        << " deg of the truth, or the truth inside the answer's own 99.9 % confidence region "
           "(its covariance). Correct by that region only (farther than the tolerance): "
        << beyond.str() << ".\n";
  if (opt.verbose) table << calibration.Table();
  std::cout << table.str();
  if (!opt.out_path.empty()) WriteFileAtomically(opt.out_path, table.str());
  if (diagnosis) WriteFileAtomically(opt.diagnose_path, diagnosis->str());
  return kExitOk;
}

}  // namespace

void AddBenchMatch(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<BenchMatchOptions>();
  CLI::App* cmd = BenchGroup(cli)->add_subcommand(
      "match",
      "The paper's Table 3: synthetic scenes of the hall localised by the "
      "interpretation tree and by the hypothesise-and-test baseline");
  cmd->add_option("--model", opt->model_path, "Model")->capture_default_str();
  cmd->add_option("--count", opt->count, "Scenes per series")->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of the scenes")->capture_default_str();
  cmd->add_option("--series", opt->series, "Priors: qi1 qi2 qi3 wide, or global (no prior)")
      ->capture_default_str();
  cmd->add_flag("!--no-baseline", opt->baseline, "Skip the baseline matcher");
  cmd->add_option("--baseline-samples", opt->baseline_samples,
                  "Random pairs the baseline may draw per case")
      ->capture_default_str();
  cmd->add_option("--clutter", opt->clutter,
                  "Clutter lines per scene (default: the paper's 5 to 12), e.g. 200 for the "
                  "search budget");
  cmd->add_option("--parallel-clutter", opt->parallel_clutter,
                  "Unmodelled lines per scene 2-8 px beside model lines (synth's option)");
  cmd->add_option("--out", opt->out_path, "Also write the table (Markdown) to this file");
  cmd->add_option("--diagnose", opt->diagnose_path,
                  "Write a JSON line per scene the tree does not answer correctly: where the "
                  "true correspondences are lost (matching/evaluation/diagnosis.h); and a short "
                  "one per correct answer whose search budget ran out");
  cmd->add_flag("--verbose", opt->verbose,
                "Also print the developer's table: the posterior of the doubted unreported "
                "groups against the truth");
  cmd->add_option("--only", opt->only,
                  "Run only these scene indices (0-based, of the --count generated; debugging)")
      ->delimiter(',');
  cmd->callback([opt, action, cmd] {
    if (opt->count < 1) throw CLI::ValidationError("--count", "must be at least 1");
    if (opt->clutter < 0) throw CLI::ValidationError("--clutter", "must be at least 0");
    if (opt->parallel_clutter < 0) {
      throw CLI::ValidationError("--parallel-clutter", "must be at least 0");
    }
    RefuseUnless(*cmd, opt->baseline, {"--baseline-samples"}, "not with --no-baseline");
    *action = [opt] { return RunBenchMatch(*opt); };
  });
}

}  // namespace linetrack::app
