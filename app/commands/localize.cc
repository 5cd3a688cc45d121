// `linetrack localize`: camera pose from image line segments and a rough prior, one case from
// flags or many from a JSON-lines batch file.
#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>

#include "app/commands.h"
#include "app/image_overlay.h"
#include "app/localize_image.h"
#include "app/localize_io.h"
#include "matching/evaluation/baseline_sampler.h"
#include "matching/lines/line_extractor.h"
#include "models/errors.h"

namespace linetrack::app {
namespace {

struct LocalizeOptions {
  std::string model_path, camera_path, camera_name, lines_path, prior_text, batch_path;
  double delta_t = 0.0, delta_phi_deg = 0.0, height = 0.0, tilt_deg = 0.0;
  std::string method = "tree";
  bool json = false;
  // From an image (--image) instead of --lines: the line extractor's flags and an overlay.
  std::string image_path, overlay_path;
  LineFlags lines;
  // Matcher noise: "PX,DEG" (default: the paper's for --lines, the extractor's for --image) and
  // the relative focal-length error of the camera file (default the paper's 2 %).
  std::string line_noise;
  double focal_error = LineNoise().focal_relative;
};

LocalizerOptions MatcherOptions(const LocalizeOptions& opt) {
  LocalizerOptions options;
  if (!opt.image_path.empty()) options.noise = DetectedLineNoise();
  if (!opt.line_noise.empty()) {
    const std::vector<double> v = ParseNumbers(opt.line_noise, 2, "--line-noise");
    options.noise.offset_px = v[0];
    options.noise.angle_deg = v[1];
  }
  options.noise.focal_relative = opt.focal_error;
  std::string why;
  if (!options.noise.Check(&why)) throw InputError("--line-noise/--focal-error: " + why);
  if (opt.method == "baseline") {
    options.method = MatchMethod::kHypothesizeAndTest;
    options.sampler = BaselineSampler(BaselineOptions());
  }
  return options;
}

double Milliseconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since)
      .count();
}

int RunBatch(const LocalizeOptions& opt) {
  std::ifstream in(opt.batch_path);
  std::error_code ec;
  if (!in || !std::filesystem::is_regular_file(opt.batch_path, ec)) {
    throw InputError(Located(opt.batch_path, 0, "cannot read the batch file"));
  }
  const std::string base_dir = std::filesystem::path(opt.batch_path).parent_path().string();
  LocalizerCache cache(MatcherOptions(opt));
  std::string row;
  int number = 0, found = 0, cases = 0;
  while (std::getline(in, row)) {
    ++number;
    if (row.find_first_not_of(" \t\r") == std::string::npos) continue;
    ++cases;
    std::string id = "line-" + std::to_string(number);
    try {
      const nlohmann::json json = nlohmann::json::parse(row);
      if (json.is_object() && json.contains("id")) {
        id = json["id"].is_string() ? json["id"].get<std::string>() : json["id"].dump();
      }
      BatchCase c = ParseBatchCase(json, base_dir);
      const Localizer& localizer = cache.Get(c.model_path, c.camera_path, c.camera_name);
      const auto start = std::chrono::steady_clock::now();
      const LocalizationResult result = localizer.Localize(c.problem);
      const double ms = Milliseconds(start);
      found += result.found ? 1 : 0;
      std::cout << ResultToJson(id, result, ms).dump() << "\n";
    } catch (const nlohmann::json::parse_error&) {
      std::cout << nlohmann::ordered_json{{"id", id},
                                          {"found", false},
                                          {"error",
                                           Located(opt.batch_path, number, "not valid JSON")}}
                       .dump()
                << "\n";
    } catch (const InputError& e) {
      std::cout << nlohmann::ordered_json{{"id", id},
                                          {"found", false},
                                          {"error", Located(opt.batch_path, number, e.what())}}
                       .dump()
                << "\n";
    }
  }
  std::cout.flush();
  spdlog::info("{} cases, {} localised", cases, found);
  return kExitOk;
}

int RunSingle(const LocalizeOptions& opt) {
  LocalizationProblem problem;
  problem.prior = ParsePrior(opt.prior_text, "--prior");
  problem.delta_t = opt.delta_t;
  problem.delta_phi = DegToRad(opt.delta_phi_deg);
  problem.height = opt.height;
  problem.tilt = DegToRad(opt.tilt_deg);
  const std::string& source = opt.image_path.empty() ? opt.lines_path : opt.image_path;
  std::optional<ImageLines> image;
  if (!opt.image_path.empty()) {
    if (!opt.overlay_path.empty()) CheckPngOutput(opt.overlay_path, "--overlay");
    image = ExtractImageLines(opt.image_path, opt.camera_path, opt.camera_name, opt.lines);
    problem.lines = image->segments;
  } else {
    problem.lines = ReadLinesCsv(opt.lines_path);
  }
  try {
    if (!problem.lines.empty()) CheckProblem(problem);
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  LocalizerCache cache(MatcherOptions(opt));
  const Localizer& localizer = cache.Get(opt.model_path, opt.camera_path, opt.camera_name);
  const auto start = std::chrono::steady_clock::now();
  LocalizationResult result;
  if (problem.lines.empty()) {
    result.reason = "no line segments in the image";  // an image may show none: not bad input
  } else {
    result = localizer.Localize(problem);
  }
  const double ms = Milliseconds(start);
  if (image && !opt.overlay_path.empty()) {
    WriteFileAtomically(
        opt.overlay_path,
        LocalizationOverlayPng(*image, *cache.Model(opt.model_path).model, result, ms));
  }
  if (image && !opt.json) {
    std::cout << "lines     " << image->segments.size() << " segments (" << image->detector << ", "
              << std::fixed << std::setprecision(2) << image->ms << " ms)\n";
  }
  if (opt.json) {
    nlohmann::ordered_json json =
        ResultToJson(std::filesystem::path(source).stem().string(), result, ms);
    if (image) {
      json["lines"] = image->segments.size();
      json["lines_ms"] = image->ms;
    }
    std::cout << json.dump(2) << std::endl;
  } else if (result.found) {
    std::cout << std::fixed << std::setprecision(3) << "pose      x " << result.pose.x << " m, y "
              << result.pose.y << " m, heading " << std::setprecision(2)
              << RadToDeg(WrapAngle(result.pose.heading)) << " deg\n"
              << "matches   " << result.matches.size() << " (edge:line";
    for (const auto& [e, l] : result.matches)
      std::cout << " " << e << ":" << l;
    std::cout << ")\nscore     " << result.score_px << " px, support " << result.support
              << "\nsearch    " << result.candidate_edges << " candidate edges, "
              << result.hypotheses << " hypotheses, " << ms << " ms\n";
  } else {
    std::cout << "no pose: " << result.reason << " (" << result.hypotheses << " hypotheses, "
              << std::fixed << std::setprecision(2) << ms << " ms)\n";
  }
  return result.found ? kExitOk : kExitJobFailed;
}

}  // namespace

void AddLocalize(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<LocalizeOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "localize",
      "Camera pose from image line segments against a .cao model, from a rough prior "
      "(interpretation-tree matcher after Ait Aider et al. 2005)");
  cmd->add_option("--model", opt->model_path, "ViSP .cao model");
  cmd->add_option("--camera", opt->camera_path, "ViSP camera XML (undistorted pixels)");
  cmd->add_option("--camera-name", opt->camera_name, "Camera name in the XML (default: first)");
  cmd->add_option("--lines", opt->lines_path, "CSV of segments u1,v1,u2,v2 in pixels");
  cmd->add_option("--image", opt->image_path,
                  "Image to extract the segments from instead of --lines (see linetrack lines)");
  cmd->add_option("--overlay", opt->overlay_path,
                  "With --image: PNG of the matched model edges (green), unmatched lines (red)");
  AddLineFlags(cmd, &opt->lines, false);
  cmd->add_option("--line-noise", opt->line_noise,
                  "Line noise OFFSET_PX,ANGLE_DEG for the matcher's margins (default 3,1 as in "
                  "the paper; with --image 1,0.3 and a 2.5 px / 2 deg match distance, "
                  "docs/lines.md)");
  cmd->add_option("--focal-error", opt->focal_error,
                  "Relative focal-length uncertainty of the camera file")
      ->capture_default_str();
  cmd->add_option("--prior", opt->prior_text, "Prior pose X,Y,HEADING_DEG (metres, degrees)");
  cmd->add_option("--delta-t", opt->delta_t, "Prior position bound (metres)");
  cmd->add_option("--delta-phi", opt->delta_phi_deg, "Prior heading bound (degrees)");
  cmd->add_option("--height", opt->height, "Camera height above the floor (metres)");
  cmd->add_option("--tilt", opt->tilt_deg, "Camera tilt below the horizontal (degrees)");
  cmd->add_flag("--json", opt->json, "Print the result as JSON (the batch format)");
  cmd->add_option("--batch", opt->batch_path,
                  "JSON-lines file of cases; prints one JSON result per line, in order");
  cmd->add_option("--method", opt->method, "tree (default) or baseline (hypothesise-and-test)")
      ->check(CLI::IsMember({"tree", "baseline"}));
  cmd->callback([opt, action, cmd] {
    if (!opt->batch_path.empty()) {
      *action = [opt] { return RunBatch(*opt); };
      return;
    }
    for (const char* flag :
         {"--model", "--camera", "--prior", "--delta-t", "--delta-phi", "--height", "--tilt"}) {
      if (cmd->count(flag) == 0) {
        throw CLI::RequiredError(std::string(flag) + " is required without --batch");
      }
    }
    if (cmd->count("--lines") + cmd->count("--image") != 1) {
      throw CLI::RequiredError("give one of --lines and --image (without --batch)");
    }
    if (cmd->count("--overlay") > 0 && cmd->count("--image") == 0) {
      throw CLI::ValidationError("--overlay", "draws over an --image");
    }
    *action = [opt] { return RunSingle(*opt); };
  });
}

}  // namespace linetrack::app
