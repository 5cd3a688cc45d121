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
#include "app/localize_io.h"
#include "models/errors.h"

namespace linetrack::app {
namespace {

struct LocalizeOptions {
  std::string model_path, camera_path, camera_name, lines_path, prior_text, batch_path;
  double delta_t = 0.0, delta_phi_deg = 0.0, height = 0.0, tilt_deg = 0.0;
  std::string method = "tree";
  bool json = false;
};

LocalizerOptions MatcherOptions(const LocalizeOptions& opt) {
  LocalizerOptions options;
  if (opt.method == "baseline") options.method = MatchMethod::kHypothesizeAndTest;
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
  problem.lines = ReadLinesCsv(opt.lines_path);
  try {
    CheckProblem(problem);
  } catch (const InputError& e) {
    throw InputError(opt.lines_path + ": " + e.what());
  }
  LocalizerCache cache(MatcherOptions(opt));
  const Localizer& localizer = cache.Get(opt.model_path, opt.camera_path, opt.camera_name);
  const auto start = std::chrono::steady_clock::now();
  const LocalizationResult result = localizer.Localize(problem);
  const double ms = Milliseconds(start);
  if (opt.json) {
    std::cout
        << ResultToJson(std::filesystem::path(opt.lines_path).stem().string(), result, ms).dump(2)
        << std::endl;
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
    for (const char* flag : {"--model", "--camera", "--lines", "--prior", "--delta-t",
                             "--delta-phi", "--height", "--tilt"}) {
      if (cmd->count(flag) == 0) {
        throw CLI::RequiredError(std::string(flag) + " is required without --batch");
      }
    }
    *action = [opt] { return RunSingle(*opt); };
  });
}

}  // namespace linetrack::app
