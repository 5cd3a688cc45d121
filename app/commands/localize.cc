// `linetrack localize`: camera pose from image line segments and a rough prior, or with no prior
// at all (--global), one case from flags or many from a JSON-lines batch file.
#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>

#include "app/commands.h"
#include "app/image_overlay.h"
#include "app/integrity_output.h"
#include "app/lines_csv.h"
#include "app/localize_image.h"
#include "app/localize_io.h"
#include "matching/evaluation/baseline_sampler.h"
#include "matching/lines/line_extractor.h"
#include "models/errors.h"
#include "models/text_format.h"
#include "tracking/integrity/image_pose_check.h"
#include "tracking/tracker/image_undistorter.h"
#include "tracking/tracker/relocalizer.h"

namespace linetrack::app {
namespace {

struct LocalizeOptions {
  std::string model_path, camera_path, camera_name, lines_path, prior_text, batch_path;
  // The prior's bounds default to those of `replay`'s first prior (the paper's QI3).
  double delta_t = SearchBounds().delta_t;
  double delta_phi_deg = RadToDeg(SearchBounds().delta_phi);
  double height = 0.0, tilt_deg = 0.0;
  int storey = -1;
  double floor_z = std::numeric_limits<double>::quiet_NaN();
  std::string method = "tree";
  bool json = false;
  bool global = false;  // no prior: heading candidates searched over the whole navigable area
  // From an image (--image) instead of --lines: the line extractor's flags and an overlay.
  std::string image_path, overlay_path;
  LineFlags lines;
  // Matcher noise: "PX,DEG" (default: the paper's for --lines, the extractor's for --image) and
  // the relative focal-length error of the camera file (default the paper's 2 %).
  std::string line_noise;
  double focal_error = LineNoise().focal_relative;
  // With --image: the answer's covariance and protection levels (its alert limit and the
  // calibration and model uncertainty).
  IntegrityFlags integrity;
};

// The integrity of the matcher's answer on its image: the moving edges and their sub-pixel points
// at the answer (known height, tilt and roll).
PoseUncertainty CheckAnswer(const LocalizeOptions& opt, const ImageLines& image,
                            const LocalizationProblem& problem, const LocalizationResult& result,
                            const IntegrityOptions& options) {
  CameraIntrinsics camera = image.camera;
  if (camera.width <= 0) {  // a camera file without the image size: the image's
    camera.width = static_cast<int>(image.image.getWidth());
    camera.height = static_cast<int>(image.image.getHeight());
  }
  EdgeTracker tracker(opt.model_path, camera, TrackerSettings());
  ImageUndistorter undistorter(camera);
  return UncertaintyOf(
      CheckPoseOnImage(&tracker, undistorter.Apply(image.image), result.cam_from_world,
                       KnownHeightTilt{problem.height, problem.tilt, problem.roll}, options));
}

// An answer whose protection levels exceed the alert limit is no answer: "ambiguous" when the
// matcher compared rivals (listed), else "none"; the candidate stays in the JSON with its
// covariance.
void WithholdAnswer(const LocalizationResult& result, const PoseUncertainty& u,
                    nlohmann::ordered_json* json) {
  (*json)["found"] = false;
  (*json)["answer"] = result.finalists.size() > 1 ? "ambiguous" : "none";
  if (json->contains("ambiguous")) (*json)["ambiguous"] = result.finalists.size() > 1;  // global
  (*json)["reason"] = "the answer is not within the alert limit: " + u.reason;
  (*json)["candidate"] = (*json)["pose"];
  (*json)["pose"] = nullptr;
  (*json)["cMo"] = nullptr;
  nlohmann::ordered_json rivals = nlohmann::ordered_json::array();
  for (const Finalist& f : result.finalists) {
    rivals.push_back({{"x", f.pose.x},
                      {"y", f.pose.y},
                      {"heading_deg", RadToDeg(WrapAngle(f.pose.heading))},
                      {"matched_edges", f.matched_edges},
                      {"mean_distance_px", f.mean_distance_px}});
  }
  (*json)["rivals"] = rivals;
}

// Why a global answer from line segments alone is no answer: the global mode's verification can
// accept a wrong pose when its searches miss the truth (docs/global.md), and only the image's
// integrity check (--image) can tell.
constexpr const char* kUnverifiedGlobal =
    "a global answer from line segments alone is not verified: give the image (--image) so "
    "that its integrity is checked";

// A found global answer without an image becomes a candidate: "found" false, "answer"
// "unverified", the pose moved to "candidate".
void MarkUnverified(nlohmann::ordered_json* json) {
  if (!(*json)["found"].get<bool>()) return;
  (*json)["found"] = false;
  (*json)["answer"] = "unverified";
  (*json)["reason"] = kUnverifiedGlobal;
  (*json)["candidate"] = (*json)["pose"];
  (*json)["pose"] = nullptr;
  (*json)["cMo"] = nullptr;
}

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
    nlohmann::json id = "line-" + std::to_string(number);  // a case without an id: its line
    try {
      const nlohmann::json json = nlohmann::json::parse(row);
      if (json.is_object() && json.contains("id")) id = json["id"];
      BatchCase c = ParseBatchCase(json, base_dir);
      if (c.global) {
        const GlobalLocalizer& global = cache.GetGlobal(c.model_path, c.camera_path, c.camera_name);
        const WireframeModel& model = *cache.Model(c.model_path).model;
        const double z = CameraZ(model, c.problem.height, c.storey, c.floor_z);
        const auto start = std::chrono::steady_clock::now();
        const GlobalResult result = global.Localize({c.problem.lines, z, c.problem.tilt});
        nlohmann::ordered_json json =
            GlobalResultToJson(id, result, MillisecondsSince(start), &model);
        MarkUnverified(&json);
        std::cout << json.dump() << "\n";
        continue;
      }
      const Localizer& localizer = cache.Get(c.model_path, c.camera_path, c.camera_name);
      c.problem.height = CameraZ(localizer.model(), c.problem.height, c.storey, c.floor_z);
      const auto start = std::chrono::steady_clock::now();
      const LocalizationResult result = localizer.Localize(c.problem);
      const double ms = MillisecondsSince(start);
      found += result.found ? 1 : 0;
      std::cout << ResultToJson(id, result, ms, cache.Model(c.model_path).model.get()).dump()
                << "\n";
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

// Prints an answer with no prior: the pose (PrintResult) or why none, with the rival poses.
void PrintGlobal(const GlobalResult& global, double ms) {
  std::cout << "global    " << global.searches.size() << " heading searches (";
  for (size_t i = 0; i < global.searches.size(); ++i) {
    std::cout << (i ? " " : "") << std::fixed << std::setprecision(1)
              << RadToDeg(WrapAngle(global.searches[i].heading));
  }
  std::cout << " deg)\n";
  if (global.found) return;
  std::cout << "no pose: " << global.reason << " (" << std::setprecision(2) << ms << " ms)\n";
  for (const Pose3Dof& p : global.rivals) {
    std::cout << "rival     x " << std::setprecision(3) << p.x << " m, y " << p.y << " m, heading "
              << std::setprecision(2) << RadToDeg(WrapAngle(p.heading)) << " deg\n";
  }
}

// The result as text: the pose and each match with its edge's name, or why there is none.
void PrintResult(const LocalizationResult& result, const WireframeModel& model, double ms) {
  if (result.found) {
    std::cout << std::fixed << std::setprecision(3) << "pose      x " << result.pose.x << " m, y "
              << result.pose.y << " m, heading " << std::setprecision(2)
              << RadToDeg(WrapAngle(result.pose.heading)) << " deg\n"
              << "matches   " << result.matches.size() << " (model edge <- image line)\n";
    for (const auto& [e, l] : result.matches) {
      const std::string& name = model.edges().at(static_cast<size_t>(e)).name;
      std::cout << "          edge " << e << (name.empty() ? "" : " " + name) << " <- line " << l
                << "\n";
    }
    std::cout << "score     " << result.score_px << " px, support " << result.support
              << "\nsearch    " << result.candidate_edges << " candidate edges, "
              << result.hypotheses << " hypotheses, " << ms << " ms\n";
  } else {
    std::cout << "no pose: " << result.reason << " (" << result.hypotheses << " hypotheses, "
              << std::fixed << std::setprecision(2) << ms << " ms)\n";
  }
}

int RunSingle(const LocalizeOptions& opt) {
  CheckHeight(opt.height, "--height");
  LocalizationProblem problem;
  if (!opt.global) {
    problem.prior = ParsePrior(opt.prior_text, "--prior");
    problem.delta_t = opt.delta_t;
    problem.delta_phi = DegToRad(opt.delta_phi_deg);
  }
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
    if (!problem.lines.empty() && !opt.global) CheckProblem(problem);
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  const IntegrityOptions integrity_options = opt.integrity.Options();
  LocalizerCache cache(MatcherOptions(opt));
  const Localizer& localizer = cache.Get(opt.model_path, opt.camera_path, opt.camera_name);
  const GlobalLocalizer* global =
      opt.global ? &cache.GetGlobal(opt.model_path, opt.camera_path, opt.camera_name) : nullptr;
  problem.height = CameraZ(localizer.model(), opt.height, opt.storey, opt.floor_z);
  const auto start = std::chrono::steady_clock::now();
  LocalizationResult result;
  std::optional<GlobalResult> global_result;
  try {
    if (problem.lines.empty()) {
      result.reason = "no line segments in the image";  // an image may show none: not bad input
    } else if (global) {
      global_result = global->Localize({problem.lines, problem.height, problem.tilt});
      result = global_result->found ? global_result->best : LocalizationResult();
      result.reason = global_result->reason;
    } else {
      result = localizer.Localize(problem);
    }
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  const double ms = MillisecondsSince(start);
  std::optional<PoseUncertainty> integrity;
  if (image && result.found) {
    integrity = CheckAnswer(opt, *image, problem, result, integrity_options);
  }
  const bool answered = result.found && (integrity ? integrity->status == IntegrityStatus::kTracking
                                                   : !global_result);
  if (image && !opt.overlay_path.empty()) {
    WriteFileAtomically(
        opt.overlay_path,
        LocalizationOverlayPng(*image, *cache.Model(opt.model_path).model, result, ms));
  }
  if (image && !opt.json) {
    std::cout << "lines     " << image->segments.size() << " segments (" << image->detector << ", "
              << std::fixed << std::setprecision(2) << image->ms << " ms)\n";
  }
  if (global_result && !opt.json) PrintGlobal(*global_result, ms);
  if (opt.json) {
    const std::string id = std::filesystem::path(source).stem().string();
    const WireframeModel* model = cache.Model(opt.model_path).model.get();
    nlohmann::ordered_json json = global_result ? GlobalResultToJson(id, *global_result, ms, model)
                                                : ResultToJson(id, result, ms, model);
    if (image) {
      json["lines"] = image->segments.size();
      json["lines_ms"] = image->ms;
    }
    if (integrity) {
      json["integrity"] = UncertaintyJson(*integrity);
      if (!answered) WithholdAnswer(result, *integrity, &json);
    } else if (global_result) {
      MarkUnverified(&json);
    }
    std::cout << json.dump(2) << std::endl;
  } else if (result.found && !integrity && global_result) {
    std::cout << "no answer: the candidate (x " << std::fixed << std::setprecision(3)
              << result.pose.x << ", y " << result.pose.y << ", heading " << std::setprecision(2)
              << RadToDeg(WrapAngle(result.pose.heading)) << " deg) is " << kUnverifiedGlobal
              << "\n";
  } else if (result.found && !answered) {
    std::cout << "no answer: the pose found (x " << std::fixed << std::setprecision(3)
              << result.pose.x << ", y " << result.pose.y << ", heading " << std::setprecision(2)
              << RadToDeg(WrapAngle(result.pose.heading))
              << " deg) is not within the alert limit: " << integrity->reason << " ("
              << result.finalists.size() << " rivals)\n";
  } else if (result.found || !global_result) {  // a global failure: PrintGlobal said why
    PrintResult(result, *cache.Model(opt.model_path).model, ms);
    if (integrity && result.found) {
      std::cout << std::fixed << std::setprecision(3) << "integrity " << ToString(integrity->status)
                << ": sigma x " << integrity->sigma_x_m << " m, y " << integrity->sigma_y_m
                << " m, heading " << RadToDeg(integrity->sigma_heading_rad) << " deg; protection "
                << integrity->protection_position_m << " m, "
                << RadToDeg(integrity->protection_rotation_rad) << " deg\n";
    }
  }
  return answered ? kExitOk : kExitJobFailed;
}

}  // namespace

void AddLocalize(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<LocalizeOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "localize",
      "Camera pose from image line segments against a .cao model, from a rough prior "
      "(interpretation-tree matcher after Ait Aider et al. 2005)");
  cmd->add_option("--model", opt->model_path, "ViSP .cao model");
  cmd->add_option("--camera", opt->camera_path,
                  "Camera file: ViSP XML, OpenCV or ROS YAML (undistorted pixels)");
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
  cmd->add_flag("--global", opt->global,
                "No prior: anywhere in the navigable area, any heading, instead of --prior, "
                "--delta-t and --delta-phi (docs/global.md)");
  cmd->add_option("--delta-t", opt->delta_t, "Prior position bound (metres)")
      ->capture_default_str();
  cmd->add_option("--delta-phi", opt->delta_phi_deg, "Prior heading bound (degrees)")
      ->capture_default_str();
  cmd->add_option("--height", opt->height, "Camera height above the floor (metres)");
  cmd->add_option("--storey", opt->storey,
                  "The storey the camera stands on (0 the lowest, default); --height is above "
                  "its floor")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--floor-z", opt->floor_z,
                  "World z of the floor the camera stands on (metres), instead of --storey");
  cmd->add_option("--tilt", opt->tilt_deg, "Camera tilt below the horizontal (degrees)");
  cmd->add_flag("--json", opt->json, "Print the result as JSON (the batch format)");
  AddIntegrityFlags(cmd, &opt->integrity);
  cmd->add_option("--batch", opt->batch_path,
                  "JSON-lines file of cases; prints one JSON result per line, in order");
  cmd->add_option("--method", opt->method, "tree (default) or baseline (hypothesise-and-test)")
      ->check(CLI::IsMember({"tree", "baseline"}));
  cmd->callback([opt, action, cmd] {
    const bool batch = !opt->batch_path.empty();
    RefuseUnless(
        *cmd, !batch,
        {"--model", "--camera", "--camera-name", "--lines", "--image", "--overlay", "--prior",
         "--delta-t", "--delta-phi", "--height", "--storey", "--floor-z", "--tilt", "--json"},
        "not with --batch (each case of the batch gives its own)");
    RefuseUnless(*cmd, cmd->count("--image") > 0,
                 {"--overlay", "--detector", "--min-length", "--roi", "--no-merge", "--undistort"},
                 "applies to the lines extracted from an --image");
    if (batch) {
      *action = [opt] { return RunBatch(*opt); };
      return;
    }
    for (const char* flag : {"--prior", "--delta-t", "--delta-phi"}) {
      if (opt->global && cmd->count(flag) > 0) {
        throw CLI::ValidationError(flag, "is not given with --global");
      }
    }
    if (!opt->global && cmd->count("--prior") == 0) {
      throw CLI::ValidationError("--prior", "required without --batch or --global");
    }
    for (const char* flag : {"--model", "--camera", "--height", "--tilt"}) {
      if (cmd->count(flag) == 0) throw CLI::ValidationError(flag, "required without --batch");
    }
    if (cmd->count("--lines") + cmd->count("--image") != 1) {
      throw CLI::ValidationError("--lines, --image", "give one of them (without --batch)");
    }
    *action = [opt] { return RunSingle(*opt); };
  });
}

}  // namespace linetrack::app
