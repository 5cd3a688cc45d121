// `linetrack synth`: synthetic localisation cases after the paper's section 4.1, written as a
// `linetrack localize --batch` file with its ground truth beside it (docs/synth.md).
#include <spdlog/spdlog.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/commands.h"
#include "app/model_loading.h"
#include "models/errors.h"
#include "models/synth/synthetic_scenes.h"

namespace linetrack::app {
namespace {

namespace fs = std::filesystem;

struct SynthCommandOptions {
  std::string model_path, out_dir, camera_path;
  int count = 430;
  uint64_t seed = 1;
  int qi = 0;  // 0: not given
  double delta_t = 0.0, delta_phi_deg = 0.0;
  bool has_delta_t = false, has_delta_phi = false;
  std::string height_range = "1.2,1.5", tilt_range = "0,10";
  double calibration_sigma = SyntheticSceneOptions().calibration_sigma;
  double angle_sigma_deg = RadToDeg(SyntheticSceneOptions().angle_sigma);
  double offset_sigma_px = SyntheticSceneOptions().offset_sigma_px;
  int parallel_clutter = 0;  // near-parallel unmodelled lines per scene (0: none)
  bool exact = false;
  int storey = 0;  // the storey the poses are drawn on
};

// "LO,HI" -> two finite numbers with LO <= HI; throws InputError naming `flag`.
std::pair<double, double> ParseRange(const std::string& text, const std::string& flag) {
  double lo = 0.0, hi = 0.0;
  char comma = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%lf %c %lf %c", &lo, &comma, &hi, &extra) != 3 || comma != ',' ||
      !std::isfinite(lo) || !std::isfinite(hi) || lo > hi) {
    throw InputError(flag + ": expected LO,HI with LO <= HI, got '" + text + "'");
  }
  return {lo, hi};
}

std::string ReadWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw InputError(Located(path, 0, "cannot read the file"));
  return text.str();
}

// The text of a fresh ViSP camera file for `camera` (written through a temporary file, since
// WriteCameraXml writes to a path).
std::string CameraXmlText(const CameraIntrinsics& camera) {
  std::error_code ec;
  const fs::path tmp = fs::temp_directory_path(ec) /
                       ("linetrack-synth-camera-" + std::to_string(::getpid()) + ".xml");
  WriteCameraXml(tmp.string(), camera);
  const std::string text = ReadWholeFile(tmp.string());
  fs::remove(tmp, ec);
  return text;
}

// The library options and the id stem ("hall-qi3") from the command's flags.
SyntheticSceneOptions SceneOptions(const SynthCommandOptions& opt, std::string* id_stem) {
  SyntheticSceneOptions o;
  o.seed = opt.seed;
  o.count = opt.count;
  const auto [h_lo, h_hi] = ParseRange(opt.height_range, "--height-range");
  const auto [t_lo, t_hi] = ParseRange(opt.tilt_range, "--tilt-range");
  CheckHeight(h_lo, "--height-range");
  CheckHeight(h_hi, "--height-range");
  CheckRange(t_lo, -89.0, 89.0, "--tilt-range");
  CheckRange(t_hi, -89.0, 89.0, "--tilt-range");
  o.height_min = h_lo;
  o.height_max = h_hi;
  o.tilt_min = DegToRad(t_lo);
  o.tilt_max = DegToRad(t_hi);
  const bool custom = opt.has_delta_t || opt.has_delta_phi;
  if (custom && opt.qi != 0) throw InputError("--qi and --delta-t/--delta-phi are exclusive");
  if (opt.has_delta_t != opt.has_delta_phi) {
    throw InputError("--delta-t and --delta-phi go together (or use --qi)");
  }
  const std::string stem = fs::path(opt.model_path).stem().string();
  if (custom) {
    CheckRange(opt.delta_t, 0.0, 100.0, "--delta-t");
    CheckRange(opt.delta_phi_deg, 1e-6, 180.0, "--delta-phi");
    o.delta_t = opt.delta_t;
    o.delta_phi = DegToRad(opt.delta_phi_deg);
    char buffer[64];
    std::snprintf(buffer, sizeof(buffer), "-dt%g-dphi%g", opt.delta_t, opt.delta_phi_deg);
    *id_stem = stem + buffer;
  } else {
    const PriorBounds bounds = QualityIndexBounds(opt.qi == 0 ? 1 : opt.qi);
    o.delta_t = bounds.delta_t;
    o.delta_phi = bounds.delta_phi;
    *id_stem = stem + "-qi" + std::to_string(opt.qi == 0 ? 1 : opt.qi);
  }
  CheckRange(opt.calibration_sigma, 0.0, 0.5, "--calibration-sigma");
  CheckRange(opt.angle_sigma_deg, 0.0, 45.0, "--angle-sigma");
  CheckRange(opt.offset_sigma_px, 0.0, 1000.0, "--offset-sigma");
  o.calibration_sigma = opt.exact ? 0.0 : opt.calibration_sigma;
  o.angle_sigma = opt.exact ? 0.0 : DegToRad(opt.angle_sigma_deg);
  o.offset_sigma_px = opt.exact ? 0.0 : opt.offset_sigma_px;
  if (opt.exact) o.shorten_max = o.split_probability = 0.0;
  o.parallel_clutter = opt.parallel_clutter;
  if (!opt.camera_path.empty()) {
    o.camera = LoadCamera(opt.camera_path);
    if (o.camera.width <= 0 || o.camera.height <= 0) {
      throw InputError(Located(opt.camera_path, 0, "the camera file gives no image size"));
    }
  }
  std::string why;
  if (!o.Check(&why)) throw InputError(why);
  return o;
}

// Heights in the files are above the storey's floor; "storey" is written for a storey above 0.
nlohmann::ordered_json CaseJson(const SyntheticScene& s, const std::string& id,
                                const std::string& model, const SyntheticSceneOptions& o) {
  nlohmann::ordered_json lines = nlohmann::ordered_json::array();
  for (const Segment2& l : s.lines)
    lines.push_back({l.a.x(), l.a.y(), l.b.x(), l.b.y()});
  nlohmann::ordered_json json = {{"id", id},
                                 {"model", model},
                                 {"camera", "camera.xml"},
                                 {"lines", lines},
                                 {"prior", {s.prior.x, s.prior.y, RadToDeg(s.prior.heading)}},
                                 {"delta_t", s.delta_t},
                                 {"delta_phi", RadToDeg(s.delta_phi)},
                                 {"height", s.height - o.floor_z},
                                 {"tilt", RadToDeg(s.tilt)}};
  if (o.storey > 0) json["storey"] = o.storey;
  return json;
}

nlohmann::ordered_json TruthJson(const SyntheticScene& s, const std::string& id,
                                 const SyntheticSceneOptions& o) {
  nlohmann::ordered_json cmo = nlohmann::ordered_json::array();
  const Eigen::Matrix4d m = CamFromWorld(s.truth).matrix();
  for (int r = 0; r < 4; ++r)
    cmo.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  nlohmann::ordered_json matches = nlohmann::ordered_json::array();
  for (const auto& [edge, line] : s.matches)
    matches.push_back({edge, line});
  return {{"id", id},
          {"pose",
           {{"x", s.truth.x},
            {"y", s.truth.y},
            {"heading_deg", RadToDeg(s.truth.heading)},
            {"height", s.truth.height - o.floor_z},
            {"tilt_deg", RadToDeg(s.truth.tilt)}}},
          {"cMo", cmo},
          {"matches", matches},
          {"clutter", s.clutter},
          {"vertical_clutter", s.vertical_clutter},
          {"calibration_scale", 1.0 + s.calibration_error}};
}

// The model path as the batch file should hold it: relative to the output folder when the two
// share a folder below the root, else absolute.
std::string ModelPathFrom(const std::string& model_path, const std::string& out_dir) {
  std::error_code ec;
  const fs::path model = fs::weakly_canonical(fs::absolute(model_path), ec);
  const fs::path out = fs::weakly_canonical(fs::absolute(out_dir), ec);
  auto m = model.begin(), o = out.begin();
  int shared = 0;
  for (; m != model.end() && o != out.end() && *m == *o; ++m, ++o)
    ++shared;
  const fs::path relative = model.lexically_relative(out);
  return shared > 1 && !relative.empty() ? relative.string() : model.string();
}

int RunSynth(const SynthCommandOptions& opt) {
  if (opt.count <= 0) throw InputError("--count: must be > 0");
  std::string id_stem;
  SyntheticSceneOptions options = SceneOptions(opt, &id_stem);
  const std::string camera_xml = opt.camera_path.empty() ? "" : ReadWholeFile(opt.camera_path);
  const WireframeModel model = LoadModel(opt.model_path);
  const NavigableArea area = NavigableArea::FromModel(model);
  if (opt.storey >= static_cast<int>(model.storeys().size())) {
    throw InputError("--storey: " + opt.model_path + " has " +
                     std::to_string(model.storeys().size()) + " storeys (0 is the lowest)");
  }
  options.storey = opt.storey;
  options.floor_z = model.storeys()[opt.storey].floor_z;
  const OcclusionTester occlusion(model);

  const auto start = std::chrono::steady_clock::now();
  const std::string model_ref = ModelPathFrom(opt.model_path, opt.out_dir);
  std::ostringstream cases, truth;
  int model_lines = 0, clutter_lines = 0, attempts = 0;
  auto last_report = start;
  for (int i = 0; i < opt.count; ++i) {
    const SyntheticScene scene = GenerateScene(model, occlusion, area, options, i);
    char index[16];
    std::snprintf(index, sizeof(index), "-%05d", i);
    const std::string id = id_stem + index;
    cases << CaseJson(scene, id, model_ref, options).dump() << "\n";
    truth << TruthJson(scene, id, options).dump() << "\n";
    model_lines += static_cast<int>(scene.matches.size());
    clutter_lines += static_cast<int>(scene.clutter.size());
    attempts += scene.attempts;
    if (std::chrono::steady_clock::now() - last_report > std::chrono::seconds(2)) {
      last_report = std::chrono::steady_clock::now();
      spdlog::info("generated {}/{} scenes", i + 1, opt.count);
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const std::string camera_text = camera_xml.empty() ? CameraXmlText(options.camera) : camera_xml;
  EnsureDirectory(opt.out_dir);
  const fs::path out(opt.out_dir);
  WriteFileAtomically((out / "camera.xml").string(), camera_text);
  WriteFileAtomically((out / "truth.jsonl").string(), truth.str());
  WriteFileAtomically((out / "cases.jsonl").string(), cases.str());
  std::cout << std::fixed << std::setprecision(2) << "wrote " << opt.count << " cases to "
            << (out / "cases.jsonl").string() << " (delta_t " << options.delta_t << " m, delta_phi "
            << RadToDeg(options.delta_phi) << " deg): " << 1.0 * model_lines / opt.count
            << " model lines and " << 1.0 * clutter_lines / opt.count
            << " clutter lines per scene, " << attempts << " poses drawn, " << seconds << " s"
            << std::endl;
  return kExitOk;
}

}  // namespace

void AddSynth(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<SynthCommandOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "synth",
      "Synthetic localisation cases (paper section 4.1): random poses in the navigable area, "
      "noisy and fragmented model lines, clutter, priors; writes cases.jsonl (the localize "
      "--batch format), truth.jsonl and camera.xml");
  cmd->add_option("--model", opt->model_path, "ViSP .cao model")->required();
  cmd->add_option("--out", opt->out_dir, "Output folder (created when missing)")->required();
  cmd->add_option("--count", opt->count, "Number of scenes")->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Random seed")->capture_default_str();
  cmd->add_option("--qi", opt->qi, "Prior quality index of the paper's Table 2 (default 1)")
      ->check(CLI::IsMember({1, 2, 3}));
  cmd->add_option("--delta-t", opt->delta_t, "Prior position bound (metres), with --delta-phi");
  cmd->add_option("--delta-phi", opt->delta_phi_deg, "Prior heading bound (degrees)");
  cmd->add_option("--storey", opt->storey,
                  "Draw the poses on this storey (0 the lowest); heights are above its floor")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--height-range", opt->height_range,
                  "Camera height range LO,HI above the floor (metres)")
      ->capture_default_str();
  cmd->add_option("--tilt-range", opt->tilt_range, "Camera tilt range LO,HI (degrees)")
      ->capture_default_str();
  cmd->add_option(
      "--camera", opt->camera_path,
      "Camera file: ViSP XML, OpenCV or ROS YAML (default: 640x480, px = py = 1000, centre "
      "320,240)");
  cmd->add_option("--calibration-sigma", opt->calibration_sigma,
                  "Std of the multiplicative focal-length error eps_m")
      ->capture_default_str();
  cmd->add_option("--angle-sigma", opt->angle_sigma_deg, "Std of the line angle noise (degrees)")
      ->capture_default_str();
  cmd->add_option("--offset-sigma", opt->offset_sigma_px, "Std of the line offset noise (pixels)")
      ->capture_default_str();
  cmd->add_flag("--exact", opt->exact, "No calibration error, line noise or fragmentation");
  cmd->add_option("--parallel-clutter", opt->parallel_clutter,
                  "Unmodelled lines per scene 2-8 px beside model lines (door casings, boxes "
                  "against walls; default none)");
  cmd->callback([opt, action, cmd] {
    opt->has_delta_t = cmd->count("--delta-t") > 0;
    opt->has_delta_phi = cmd->count("--delta-phi") > 0;
    RefuseUnless(*cmd, !opt->exact, {"--calibration-sigma", "--angle-sigma", "--offset-sigma"},
                 "not with --exact (no calibration error or line noise)");
    *action = [opt] { return RunSynth(*opt); };
  });
}

}  // namespace linetrack::app
