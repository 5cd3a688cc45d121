// `linetrack bench localize-image`: end to end from rendered hall images -- line extraction
// and the matcher -- on views and priors drawn as `linetrack synth` draws them, judged like
// `bench match`; failures are put down to the detector or to the matcher.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <set>
#include <sstream>

#include "app/commands.h"
#include "app/localize_image.h"
#include "app/match_outcome.h"
#include "app/model_loading.h"
#include "app/rendered_cases.h"
#include "matching/evaluation/line_evaluation.h"
#include "matching/lines/line_extractor.h"
#include "matching/localizer.h"
#include "models/errors.h"
#include "models/statistics.h"
#include "models/view_invariant_regions.h"

namespace linetrack::app {
namespace {

// The paper's accuracy on real images (Table 4): pose within these of the truth.
constexpr double kPaperPositionM = 0.2;
constexpr double kPaperHeadingDeg = 3.0;
// Model edges the detector must show for the truth to be "detected" (bench lines' criterion).
constexpr double kMinEdgeLengthPx = 40.0;
// Exact lines given to the matcher to tell detector failures from matcher failures: the
// visible pieces at least this long (synth's minimum).
constexpr double kMinExactLinePx = 15.0;

struct BenchLocalizeImageOptions {
  std::string model_path = "models/hall.cao";
  int count = 200;
  uint64_t seed = 1;
  int qi = 3;
  int clutter = 10;
  double calibration_sigma = 0.0;
  // What the matcher is told of the focal-length error (a Zhang calibration: about 0.5 %).
  double focal_error = 0.005;
  std::string detector = LineDetectorName(LineExtractionOptions().detector);
  std::string camera_path;  // empty: the paper's synthetic camera
  int max_edges = 12;       // synth's acceptance of a view: 5 to this many model edges seen
  std::string out_path;
};

using Outcome = MatchOutcome;

// Why an image was not localised correctly: the matcher fails on the exact projections too;
// it succeeds on those but not on the detections that image model edges (the detector did not
// deliver enough of them, or not accurately enough); or it succeeds on those, so the
// unmodelled lines (clutter, frame bands) led it astray.
enum class FailureCause { kMatcher, kDetector, kUnmodelledLines };
const char* const kCauseNames[] = {"matcher (fails on the exact lines too)",
                                   "detector (matcher correct on exact lines, not on the "
                                   "detected model lines)",
                                   "unmodelled lines (matcher correct on the detected model "
                                   "lines alone)"};

// Judged as `bench match` judges (JudgeMatch); a reported correspondence is true when the line
// lies along the edge's projection at the true pose.
Outcome Judge(const RenderedCase& c, const LocalizationResult& result,
              const std::vector<std::vector<int>>& true_edges_of_line) {
  const bool all_true =
      !result.matches.empty() &&
      std::all_of(result.matches.begin(), result.matches.end(), [&](const auto& m) {
        const std::vector<int>& ids = true_edges_of_line[m.second];
        return std::find(ids.begin(), ids.end(), m.first) != ids.end();
      });
  return JudgeMatch(result.found, all_true,
                    ErrorsOf(result.pose.Planar(), result.covariance, c.scene.truth.Planar()));
}

LocalizationProblem Problem(const RenderedCase& c, std::vector<Segment2> lines) {
  LocalizationProblem problem;
  problem.lines = std::move(lines);
  problem.prior = c.scene.prior;
  problem.delta_t = c.scene.delta_t;
  problem.delta_phi = c.scene.delta_phi;
  problem.height = c.scene.height;
  problem.tilt = c.scene.tilt;
  return problem;
}

FailureCause Attribute(const RenderedCase& c, const std::vector<Segment2>& lines,
                       const Localizer& localizer) {
  std::vector<Segment2> exact;
  for (const ProjectedEdge& e : c.truth) {
    if (e.image.Length() >= kMinExactLinePx) exact.push_back(e.image);
  }
  const LocalizationResult ideal = localizer.Localize(Problem(c, exact));
  if (Judge(c, ideal, TrueCorrespondences(c.truth, exact, {})) != Outcome::kCorrect) {
    return FailureCause::kMatcher;
  }
  std::vector<Segment2> modelled;
  const std::vector<std::vector<int>> ids = TrueCorrespondences(c.truth, lines, {});
  for (size_t i = 0; i < lines.size(); ++i) {
    if (!ids[i].empty()) modelled.push_back(lines[i]);
  }
  if (modelled.empty()) return FailureCause::kDetector;
  const LocalizationResult detected = localizer.Localize(Problem(c, modelled));
  return Judge(c, detected, TrueCorrespondences(c.truth, modelled, {})) == Outcome::kCorrect
             ? FailureCause::kUnmodelledLines
             : FailureCause::kDetector;
}

// Outcomes, causes and figures over the images.
struct ImageTally {
  int counts[4] = {0, 0, 0, 0};
  int causes[3] = {0, 0, 0};  // failures (not correct) by cause
  std::vector<double> lines_ms, matcher_ms, total_ms, segments, position_error, heading_error;
  int accurate = 0;  // poses (any correspondences) within the paper's real-image accuracy
  std::ostringstream failures;
};

// Extracts the lines of case `i`, localises, judges the answer and, when it is not correct,
// finds whose failure it is.
void TallyCase(size_t i, const RenderedCase& c, LineExtractor& extractor,
               const Localizer& localizer, ImageTally* tally) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<Segment2> lines = extractor(c.image);
  const auto t1 = std::chrono::steady_clock::now();
  LocalizationResult result;
  if (!lines.empty()) result = localizer.Localize(Problem(c, lines));
  const auto t2 = std::chrono::steady_clock::now();
  tally->lines_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  tally->matcher_ms.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
  tally->total_ms.push_back(std::chrono::duration<double, std::milli>(t2 - t0).count());
  tally->segments.push_back(lines.size());
  const Outcome outcome = Judge(c, result, TrueCorrespondences(c.truth, lines, {}));
  ++tally->counts[static_cast<int>(outcome)];
  const double position_error =
      std::hypot(result.pose.x - c.scene.truth.x, result.pose.y - c.scene.truth.y);
  const double heading_error =
      RadToDeg(std::abs(WrapAngle(result.pose.heading - c.scene.truth.heading)));
  if (result.found && position_error <= kPaperPositionM && heading_error <= kPaperHeadingDeg) {
    ++tally->accurate;
  }
  if (outcome == Outcome::kCorrect) {
    tally->position_error.push_back(position_error);
    tally->heading_error.push_back(heading_error);
    return;
  }
  // Whose failure: the matcher given the exact visible pieces, then only the detections
  // that image model edges (no clutter, no frame bands).
  const FailureCause cause = Attribute(c, lines, localizer);
  ++tally->causes[static_cast<int>(cause)];
  const DetectionEvaluation found = EvaluateDetections(c.observable, lines, kMinEdgeLengthPx, {});
  tally->failures << "| " << i << " | " << MatchOutcomeName(outcome) << " | " << found.found
                  << " / " << found.edges.size() << " | " << kCauseNames[static_cast<int>(cause)]
                  << " | " << (result.found ? "" : result.reason) << " |\n";
}

// The Markdown report: the set-up, the outcome table, the causes and the failures.
std::string ImageTable(const BenchLocalizeImageOptions& opt, const PriorBounds& bounds,
                       const LineNoise& noise, size_t cases, const ImageTally& t) {
  const double n = std::max<size_t>(1, cases);
  std::ostringstream table;
  table << std::fixed << cases << " rendered hall views ("
        << (opt.camera_path.empty() ? "the paper's camera, 640x480, px 1000" : opt.camera_path)
        << ", " << opt.clutter << " clutter objects, seed " << opt.seed << "), poses and QI"
        << opt.qi << " priors (" << std::setprecision(2) << bounds.delta_t << " m, "
        << std::setprecision(0) << RadToDeg(bounds.delta_phi)
        << " deg) drawn as linetrack synth draws them, calibration "
        << "error sigma " << std::setprecision(3) << opt.calibration_sigma
        << "; matcher set for detected lines (DetectedLineNoise): line noise "
        << std::setprecision(1) << noise.offset_px << " px, " << noise.angle_deg
        << " deg; focal error " << std::setprecision(3) << opt.focal_error << "; detector "
        << opt.detector << ", one thread.\n\n"
        << "| correct | no answer | wrong but accurate | wrong | pose within 0.2 m, 3 deg | "
           "lines ms (median / p90) | "
           "matcher ms (median / p90) | total ms (median / p90) | segments (median) | pose "
           "error of correct answers (median) |\n"
        << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n"
        << "| " << t.counts[0] << " (" << std::setprecision(1) << 100.0 * t.counts[0] / n
        << " %) | " << t.counts[1] << " | " << t.counts[2] << " | " << t.counts[3] << " | "
        << t.accurate << " (" << 100.0 * t.accurate / n << " %) | " << std::setprecision(2)
        << QuantileNearestRank(t.lines_ms, 0.5) << " / " << QuantileNearestRank(t.lines_ms, 0.9)
        << " | " << QuantileNearestRank(t.matcher_ms, 0.5) << " / "
        << QuantileNearestRank(t.matcher_ms, 0.9) << " | " << QuantileNearestRank(t.total_ms, 0.5)
        << " / " << QuantileNearestRank(t.total_ms, 0.9) << " | " << std::setprecision(0)
        << QuantileNearestRank(t.segments, 0.5) << " | " << std::setprecision(3)
        << QuantileNearestRank(t.position_error, 0.5) << " m, " << std::setprecision(2)
        << QuantileNearestRank(t.heading_error, 0.5) << " deg |\n\n"
        << "Not correct: " << t.causes[0] + t.causes[1] + t.causes[2]
        << "; by cause: " << t.causes[0] << " " << kCauseNames[0] << ", " << t.causes[1] << " "
        << kCauseNames[1] << ", " << t.causes[2] << " " << kCauseNames[2] << ".\n";
  if (t.causes[0] + t.causes[1] + t.causes[2] > 0) {
    table << "\n| case | outcome | observable edges >= 40 px found | cause | reason |\n"
             "| --- | --- | --- | --- | --- |\n"
          << t.failures.str();
  }
  return table.str();
}

// The rendering of the cases: the benchmark's flags in RenderedCaseOptions.
RenderedCaseOptions CaseOptions(const BenchLocalizeImageOptions& opt, const PriorBounds& bounds) {
  RenderedCaseOptions case_options;
  case_options.count = opt.count;
  case_options.seed = opt.seed;
  case_options.clutter = opt.clutter;
  case_options.calibration_sigma = opt.calibration_sigma;
  case_options.max_visible_edges = opt.max_edges;
  if (!opt.camera_path.empty()) {
    case_options.camera = LoadCamera(opt.camera_path);
    if (case_options.camera.width <= 0) {
      throw InputError(opt.camera_path + ": the camera file gives no image size");
    }
  }
  case_options.delta_t = bounds.delta_t;
  case_options.delta_phi = bounds.delta_phi;
  return case_options;
}

int RunBenchLocalizeImage(const BenchLocalizeImageOptions& opt) {
  const auto detector = ParseLineDetector(opt.detector);
  if (!detector) throw InputError("--detector: unknown detector '" + opt.detector + "'");
  const PriorBounds bounds = QualityIndexBounds(opt.qi);
  cv::setNumThreads(1);
  const WireframeModel model = LoadModel(opt.model_path);
  const NavigableArea area = NavigableArea::FromModel(model);
  const ViewInvariantRegions regions = ViewInvariantRegions::Build(model, area);
  const OcclusionTester occlusion(model);
  const RenderedCaseOptions case_options = CaseOptions(opt, bounds);
  spdlog::info("rendering {} hall views", opt.count);
  const std::vector<RenderedCase> cases = RenderCases(model, area, occlusion, case_options);

  LineExtractionOptions line_options;
  line_options.detector = *detector;
  LineExtractor extractor(line_options, case_options.camera);
  LocalizerOptions localizer_options;
  localizer_options.noise = DetectedLineNoise();
  localizer_options.noise.focal_relative = opt.focal_error;
  const Localizer localizer(model, &regions, &area, case_options.camera, localizer_options);
  ImageTally tally;
  for (size_t i = 0; i < cases.size(); ++i) {
    TallyCase(i, cases[i], extractor, localizer, &tally);
    if ((i + 1) % 50 == 0) spdlog::info("{}/{} images", i + 1, cases.size());
  }
  const std::string table = ImageTable(opt, bounds, localizer_options.noise, cases.size(), tally);
  std::cout << table;
  if (!opt.out_path.empty()) WriteFileAtomically(opt.out_path, table);
  return kExitOk;
}

}  // namespace

void AddBenchLocalizeImage(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<BenchLocalizeImageOptions>();
  CLI::App* cmd = BenchGroup(cli)->add_subcommand(
      "localize-image",
      "End to end on rendered hall views: line extraction + matcher, correct / no answer / "
      "wrong, times, and whose failures they are");
  cmd->add_option("--model", opt->model_path, "Model rendered")->capture_default_str();
  cmd->add_option("--count", opt->count, "Rendered views")->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of the views, priors and images")
      ->capture_default_str();
  cmd->add_option("--qi", opt->qi, "Prior quality index 1, 2 or 3 (the paper's Table 2)")
      ->capture_default_str();
  cmd->add_option("--clutter", opt->clutter, "Unmodelled objects in the hall")
      ->capture_default_str();
  cmd->add_option("--calibration-sigma", opt->calibration_sigma,
                  "Relative focal-length error of the images (synth uses 0.02)")
      ->capture_default_str();
  cmd->add_option("--focal-error", opt->focal_error,
                  "Relative focal-length uncertainty the matcher allows (localize --focal-error)")
      ->capture_default_str();
  cmd->add_option("--camera", opt->camera_path,
                  "Camera file of the images: ViSP XML, OpenCV or ROS YAML (default: the paper's "
                  "640x480, px = 1000)");
  cmd->add_option("--max-edges", opt->max_edges,
                  "Views show 5 to this many model edges (synth's acceptance; wider lenses see "
                  "more)")
      ->capture_default_str();
  cmd->add_option("--detector", opt->detector, "Line detector: hough, lsd, fld, edlines")
      ->capture_default_str();
  cmd->add_option("--out", opt->out_path, "Also write the table (Markdown) to this file");
  cmd->callback([opt, action] {
    if (opt->count < 1 || opt->clutter < 0 || opt->max_edges < 5) {
      throw CLI::ValidationError("--count >= 1, --clutter >= 0, --max-edges >= 5");
    }
    if (opt->qi < 1 || opt->qi > 3) throw CLI::ValidationError("--qi", "must be 1, 2 or 3");
    if (!(opt->calibration_sigma >= 0.0 && opt->calibration_sigma <= 0.2)) {
      throw CLI::ValidationError("--calibration-sigma", "must be in [0, 0.2]");
    }
    if (!(opt->focal_error >= 0.0 && opt->focal_error <= 0.2)) {
      throw CLI::ValidationError("--focal-error", "must be in [0, 0.2]");
    }
    *action = [opt] { return RunBenchLocalizeImage(*opt); };
  });
}

}  // namespace linetrack::app
