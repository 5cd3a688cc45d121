// `linetrack bench heading`: heading (and tilt) from vanishing points on rendered views of a
// model, with and without unmodelled clutter, the tilt given and estimated. A view counts when
// the detector found at least two lines along visible horizontal edges of one direction (the
// issue's condition); its error is the smallest distance from the truth to a candidate.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <sstream>

#include "app/commands.h"
#include "app/model_loading.h"
#include "matching/evaluation/line_evaluation.h"
#include "matching/heading/heading_estimator.h"
#include "matching/lines/line_extractor.h"
#include "models/errors.h"
#include "models/navigable_area.h"
#include "models/render/scene_renderer.h"
#include "models/statistics.h"
#include "models/synth/synthetic_scenes.h"

namespace linetrack::app {
namespace {

constexpr double kTargetDeg = 1.0;     // the issue: one candidate within 1 deg
constexpr double kWrongPeakDeg = 5.0;  // beyond this the vote chose another peak
constexpr int kMinLinesOfDirection = 2;

struct BenchHeadingOptions {
  std::string model_path = "models/hall.cao";
  std::string camera_path;  // empty: the paper's camera
  int count = 200;
  uint64_t seed = 1;
  int clutter = 10;
  int random_lines = 0;  // random segments added to the detected lines of the cluttered views
  std::string detector = LineDetectorName(LineExtractionOptions().detector);
  bool verbose = false;
  std::string out_path;
};

// One rendered view: its pose, detected lines and how many of them image each model direction.
struct HeadingView {
  RobotPose truth;
  std::vector<Segment2> lines;
  int lines_of_best_direction = 0;
};

RobotPose DrawPose(const NavigableArea& area, SceneRandom* random) {
  const Eigen::Vector2d lo = area.BoundsMin(), hi = area.BoundsMax();
  for (;;) {
    const Eigen::Vector2d p(random->Uniform(lo.x(), hi.x()), random->Uniform(lo.y(), hi.y()));
    if (!area.Contains(p)) continue;
    return {p.x(), p.y(), random->Uniform(-kPi, kPi), random->Uniform(1.2, 1.5),
            random->Uniform(0.0, DegToRad(10.0))};
  }
}

// Detected lines along visible horizontal edges, counted per model direction (the largest).
int LinesOfBestDirection(const WireframeModel& model, const ModelDirections& directions,
                         const std::vector<ProjectedEdge>& truth,
                         const std::vector<Segment2>& lines) {
  std::vector<int> counts(directions.angles.size(), 0);
  for (const std::vector<int>& ids : TrueCorrespondences(truth, lines, {})) {
    for (int id : ids) {
      const Eigen::Vector3d d = model.edges()[id].segment.Direction();
      if (model.edges()[id].vertical || std::abs(d.z()) > 0.05) continue;
      const double angle = std::atan2(d.y(), d.x());
      for (size_t k = 0; k < directions.angles.size(); ++k) {
        if (std::abs(std::remainder(angle - directions.angles[k], kPi)) < DegToRad(2.0)) {
          ++counts[k];
          break;
        }
      }
      break;  // one direction per line
    }
  }
  return counts.empty() ? 0 : *std::max_element(counts.begin(), counts.end());
}

// `count` random segments (20-200 px long, anywhere in the image) from the view's own stream.
std::vector<Segment2> RandomLines(const CameraIntrinsics& camera, int count, SceneRandom* random) {
  std::vector<Segment2> out;
  while (static_cast<int>(out.size()) < count) {
    const Eigen::Vector2d mid(random->Uniform(0.0, camera.width),
                              random->Uniform(0.0, camera.height));
    const double angle = random->Uniform(0.0, kPi), half = 0.5 * random->Uniform(20.0, 200.0);
    const Eigen::Vector2d d(half * std::cos(angle), half * std::sin(angle));
    Segment2 s{mid - d, mid + d};
    if (ClipSegmentToImage(camera.width, camera.height, &s) && s.Length() >= 20.0) out.push_back(s);
  }
  return out;
}

std::vector<HeadingView> RenderViews(const WireframeModel& model, const NavigableArea& area,
                                     const CameraIntrinsics& camera, const ModelDirections& dirs,
                                     const BenchHeadingOptions& opt, int clutter) {
  RenderOptions render_options;
  render_options.scene.seed = opt.seed;
  render_options.scene.clutter = clutter;
  SceneRenderer renderer(model, camera, render_options, &area);
  const OcclusionTester occlusion(model);
  LineExtractionOptions line_options;
  line_options.detector = *ParseLineDetector(opt.detector);
  LineExtractor extractor(line_options, camera);
  const CameraIntrinsics undistorted = camera.Undistorted();
  std::vector<HeadingView> views;
  for (int i = 0; i < opt.count; ++i) {
    SceneRandom random(opt.seed, static_cast<uint64_t>(i));
    HeadingView v;
    v.truth = DrawPose(area, &random);
    const Eigen::Isometry3d cam_from_world = CamFromWorld(v.truth);
    v.lines = extractor(renderer.Render(cam_from_world, i));
    if (clutter > 0) {
      for (const Segment2& s : RandomLines(undistorted, opt.random_lines, &random))
        v.lines.push_back(s);
    }
    v.lines_of_best_direction = LinesOfBestDirection(
        model, dirs, ProjectVisibleEdges(model, occlusion, cam_from_world, undistorted), v.lines);
    views.push_back(std::move(v));
    if ((i + 1) % 50 == 0)
      spdlog::info("rendered {}/{} views ({} clutter objects)", i + 1, opt.count, clutter);
  }
  return views;
}

double CandidateErrorDeg(const std::vector<double>& candidates, double truth) {
  double best = 180.0;
  for (double h : candidates)
    best = std::min(best, std::abs(RadToDeg(WrapAngle(h - truth))));
  return best;
}

// One row of the table and the failures behind it.
struct RowResult {
  int views = 0, eligible = 0, found = 0, within = 0, no_answer = 0, wrong_peak = 0, inaccurate = 0;
  std::vector<double> errors, tilt_errors, ms;
  std::ostringstream failures;
};

RowResult RunRow(const std::vector<HeadingView>& views, const CameraIntrinsics& camera,
                 const ModelDirections& dirs, bool tilt_known) {
  RowResult row;
  for (size_t i = 0; i < views.size(); ++i) {
    const HeadingView& v = views[i];
    ++row.views;
    const auto start = std::chrono::steady_clock::now();
    const HeadingCandidates r = EstimateHeading(
        v.lines, camera, tilt_known ? std::optional<double>(v.truth.tilt) : std::nullopt, dirs);
    row.ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    if (v.lines_of_best_direction < kMinLinesOfDirection) continue;
    ++row.eligible;
    row.found += r.found;
    const double error = r.found ? CandidateErrorDeg(r.BestHeadings(), v.truth.heading) : 180.0;
    row.errors.push_back(error);
    if (r.found && !tilt_known)
      row.tilt_errors.push_back(std::abs(RadToDeg(r.tilt - v.truth.tilt)));
    if (error <= kTargetDeg) {
      ++row.within;
      continue;
    }
    const char* kind = !r.found ? "no answer" : error > kWrongPeakDeg ? "wrong peak" : "inaccurate";
    (!r.found ? row.no_answer : error > kWrongPeakDeg ? row.wrong_peak : row.inaccurate)++;
    row.failures << "| " << i << " | " << std::fixed << std::setprecision(2) << v.truth.x << ", "
                 << v.truth.y << ", " << std::setprecision(1) << RadToDeg(v.truth.heading) << " | "
                 << RadToDeg(v.truth.tilt) << " | " << v.lines.size() << " | "
                 << v.lines_of_best_direction << " | " << kind << " | "
                 << (r.found ? std::to_string(r.hypotheses.front().support) : r.reason) << " | "
                 << (r.found ? RadToDeg(r.hypotheses.front().heading_sigma) : 0.0) << " | " << error
                 << " |\n";
  }
  return row;
}

int RunBenchHeading(const BenchHeadingOptions& opt) {
  if (!ParseLineDetector(opt.detector))
    throw InputError("--detector: unknown '" + opt.detector + "'");
  cv::setNumThreads(1);
  const WireframeModel model = LoadModel(opt.model_path);
  const NavigableArea area = NavigableArea::FromModel(model);
  const ModelDirections dirs = DominantDirections(model);
  CameraIntrinsics camera = PaperSyntheticCamera();
  if (!opt.camera_path.empty()) camera = ReadCameraXml(opt.camera_path);
  if (camera.width <= 0)
    throw InputError(opt.camera_path + ": the camera file gives no image size");
  std::ostringstream table, failures;
  table << opt.count << " rendered views of " << opt.model_path << " ("
        << (opt.camera_path.empty() ? "the paper's camera, 640x480, px 1000" : opt.camera_path)
        << ", seed " << opt.seed << ", detector " << opt.detector
        << "): positions uniform in the navigable area, heading uniform, height 1.2-1.5 m, tilt "
           "0-10 deg. Counted: views with at least "
        << kMinLinesOfDirection
        << " detected lines along visible horizontal edges of one direction. Error: truth to "
           "the nearest candidate.\n\n"
        << "| clutter objects | tilt | views | counted | within " << kTargetDeg
        << " deg | median error (deg) | p90 error (deg) | no answer | wrong peak (> "
        << kWrongPeakDeg << " deg) | inaccurate | tilt error median (deg) | ms (median / p99) |\n"
        << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (int clutter : {0, opt.clutter}) {
    const std::vector<HeadingView> views = RenderViews(model, area, camera, dirs, opt, clutter);
    for (bool tilt_known : {true, false}) {
      RowResult row = RunRow(views, camera.Undistorted(), dirs, tilt_known);
      const double n = std::max(1, row.eligible);
      table << std::fixed << "| " << clutter
            << (clutter > 0 && opt.random_lines > 0
                    ? " + " + std::to_string(opt.random_lines) + " random lines"
                    : "")
            << " | " << (tilt_known ? "given" : "estimated")
            << " | " << row.views << " | " << row.eligible << " | " << row.within << " ("
            << std::setprecision(1) << 100.0 * row.within / n << " %) | " << std::setprecision(3)
            << QuantileNearestRank(row.errors, 0.5) << " | " << QuantileNearestRank(row.errors, 0.9) << " | "
            << row.no_answer << " | " << row.wrong_peak << " | " << row.inaccurate << " | "
            << (tilt_known ? std::string("-") : [&] {
                 std::ostringstream s;
                 s << std::fixed << std::setprecision(3) << QuantileNearestRank(row.tilt_errors, 0.5);
                 return s.str();
               }())
            << " | " << std::setprecision(2) << QuantileNearestRank(row.ms, 0.5) << " / "
            << QuantileNearestRank(row.ms, 0.99) << " |\n";
      if (opt.verbose || (clutter == opt.clutter && tilt_known)) {
        failures << "\nFailures, " << clutter << " clutter objects, tilt "
                 << (tilt_known ? "given" : "estimated") << ":\n\n"
                 << "| view | x, y, heading | tilt | lines | lines of one direction | kind | "
                    "support or reason | sigma (deg) | error (deg) |\n| --- | --- | --- | --- | "
                    "--- | --- | --- | --- | --- |\n"
                 << row.failures.str();
      }
    }
  }
  table << failures.str();
  std::cout << table.str();
  if (!opt.out_path.empty()) WriteFileAtomically(opt.out_path, table.str());
  return kExitOk;
}

}  // namespace

void AddBenchHeading(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<BenchHeadingOptions>();
  CLI::App* cmd = BenchGroup(cli)->add_subcommand(
      "heading",
      "Heading from vanishing points on rendered views: accuracy with and without "
      "clutter, tilt given and estimated (docs/heading.md)");
  cmd->add_option("--model", opt->model_path, "Model rendered")->capture_default_str();
  cmd->add_option("--camera", opt->camera_path,
                  "Camera XML of the images (default: the paper's 640x480, px = 1000)");
  cmd->add_option("--count", opt->count, "Rendered views per clutter setting")
      ->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of the poses, scenes and images")
      ->capture_default_str();
  cmd->add_option("--clutter", opt->clutter, "Unmodelled objects of the cluttered row")
      ->capture_default_str();
  cmd->add_option("--detector", opt->detector, "Line detector: hough, lsd, fld, edlines")
      ->capture_default_str();
  cmd->add_option("--random-lines", opt->random_lines,
                  "Random segments (20-200 px) added to the lines of the cluttered views")
      ->capture_default_str();
  cmd->add_flag("--verbose", opt->verbose, "List the failures of every row");
  cmd->add_option("--out", opt->out_path, "Also write the table (Markdown) to this file");
  cmd->callback([opt, action] {
    if (opt->count < 1 || opt->clutter < 0 || opt->random_lines < 0)
      throw CLI::ValidationError("--count >= 1, --clutter >= 0, --random-lines >= 0");
    *action = [opt] { return RunBenchHeading(*opt); };
  });
}

}  // namespace linetrack::app
