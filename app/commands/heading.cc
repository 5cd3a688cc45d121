// `linetrack heading`: the camera's heading candidates (and tilt when not given) from the
// vanishing points of an image's lines against the model's dominant directions
// (matching/heading/, docs/heading.md).
//   linetrack heading IMAGE --camera C.xml --model M.cao [--tilt DEG] [--json]
//   linetrack heading --lines LINES.csv --camera C.xml --model M.cao [--tilt DEG] [--json]
#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/line_flags.h"
#include "app/lines_csv.h"
#include "app/localize_image.h"
#include "app/localize_io.h"
#include "app/model_loading.h"
#include "matching/heading/heading_estimator.h"
#include "models/errors.h"

namespace linetrack::app {
namespace {

struct HeadingCommandOptions {
  std::string image_path, lines_path, model_path;
  std::optional<double> tilt_deg;
  bool json = false;
  LineFlags lines;
};

nlohmann::ordered_json Degrees(const std::vector<double>& radians) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (double r : radians)
    out.push_back(std::round(RadToDeg(r) * 1e4) / 1e4);
  return out;
}

nlohmann::ordered_json VanishingPointJson(const VanishingPoint& vp,
                                          const ModelDirections& directions) {
  nlohmann::ordered_json j;
  j["direction"] = vp.vertical ? "vertical" : "horizontal";
  if (!vp.vertical) {
    j["model_direction_deg"] = RadToDeg(directions.angles[vp.model_direction]);
    j["bearing_deg"] = RadToDeg(vp.bearing);
  }
  j["at_infinity"] = !vp.pixel.has_value();
  if (vp.pixel) {
    j["u"] = vp.pixel->x();
    j["v"] = vp.pixel->y();
  }
  j["lines"] = vp.lines;
  return j;
}

nlohmann::ordered_json ResultJson(const HeadingCandidates& r, const ModelDirections& directions,
                                  double ms) {
  nlohmann::ordered_json j;
  j["found"] = r.found;
  if (!r.found) j["reason"] = r.reason;
  j["headings_deg"] = Degrees(r.BestHeadings());
  if (r.found) {
    j["heading_sigma_deg"] = RadToDeg(r.hypotheses.front().heading_sigma);
    j["support"] = r.hypotheses.front().support;
  }
  j["tilt_deg"] = RadToDeg(r.tilt);
  j["tilt_estimated"] = r.tilt_estimated;
  if (r.tilt_estimated) j["tilt_sigma_deg"] = RadToDeg(r.tilt_sigma);
  j["vertical_lines"] = r.vertical_lines;
  j["vanishing_points"] = nlohmann::ordered_json::array();
  for (const VanishingPoint& vp : r.vanishing_points) {
    j["vanishing_points"].push_back(VanishingPointJson(vp, directions));
  }
  j["alternatives"] = nlohmann::ordered_json::array();
  for (size_t h = 1; h < r.hypotheses.size(); ++h) {
    j["alternatives"].push_back({{"headings_deg", Degrees(r.hypotheses[h].headings)},
                                 {"support", r.hypotheses[h].support}});
  }
  j["lines"] = r.lines_used;
  j["time_ms"] = ms;
  return j;
}

void PrintText(const HeadingCandidates& r, const ModelDirections& directions) {
  std::cout << std::fixed << std::setprecision(2);
  if (!r.found) {
    std::cout << "no heading: " << r.reason << std::endl;
    return;
  }
  std::cout << "heading candidates (deg):";
  for (double h : r.BestHeadings())
    std::cout << " " << RadToDeg(h);
  std::cout << "  (" << r.hypotheses.front().support << " lines, sigma "
            << RadToDeg(r.hypotheses.front().heading_sigma) << " deg)\n";
  std::cout << "tilt " << RadToDeg(r.tilt) << " deg "
            << (r.tilt_estimated ? "(estimated)" : "(given)") << ", " << r.vertical_lines
            << " vertical lines\n";
  for (const VanishingPoint& vp : r.vanishing_points) {
    std::cout << "  vanishing point "
              << (vp.vertical ? std::string("vertical")
                              : "along " +
                                    std::to_string(static_cast<int>(std::lround(
                                        RadToDeg(directions.angles[vp.model_direction])))) +
                                    " deg");
    if (vp.pixel) {
      std::cout << " at (" << vp.pixel->x() << ", " << vp.pixel->y() << ")";
    } else {
      std::cout << " at infinity";
    }
    std::cout << ", " << vp.lines.size() << " lines\n";
  }
  std::cout.flush();
}

int RunHeading(const HeadingCommandOptions& opt) {
  if (opt.image_path.empty() == opt.lines_path.empty()) {
    throw InputError("heading: give either IMAGE or --lines");
  }
  if (opt.tilt_deg) CheckRange(*opt.tilt_deg, -89.0, 89.0, "--tilt");
  const WireframeModel model = LoadModel(opt.model_path);
  const ModelDirections directions = DominantDirections(model);
  if (directions.angles.empty()) throw InputError(opt.model_path + ": no horizontal edges");
  std::vector<Segment2> segments;
  CameraIntrinsics camera;
  if (!opt.image_path.empty()) {
    const ImageLines image =
        ExtractImageLines(opt.image_path, opt.lines.camera_path, opt.lines.camera_name, opt.lines);
    segments = image.segments;
    camera = image.camera.Undistorted();
  } else {
    segments = ReadLinesCsv(opt.lines_path);
    camera = ReadCameraXml(opt.lines.camera_path, opt.lines.camera_name).Undistorted();
  }
  std::optional<double> tilt;
  if (opt.tilt_deg) tilt = DegToRad(*opt.tilt_deg);
  const auto start = std::chrono::steady_clock::now();
  HeadingCandidates result;
  try {
    result = EstimateHeading(segments, camera, tilt, directions);
  } catch (const InputError& e) {
    throw InputError((opt.image_path.empty() ? opt.lines_path : opt.image_path) + ": " + e.what());
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (opt.json) {
    std::cout << ResultJson(result, directions, ms).dump(2) << std::endl;
  } else {
    PrintText(result, directions);
  }
  return result.found ? kExitOk : kExitJobFailed;
}

}  // namespace

void AddHeading(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<HeadingCommandOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "heading",
      "Camera heading candidates (modulo the building's symmetries) and tilt from vanishing "
      "points (docs/heading.md)");
  cmd->add_option("IMAGE", opt->image_path, "Grey or colour image (lines extracted as `lines`)");
  cmd->add_option("--lines", opt->lines_path, "CSV of segments u1,v1,u2,v2 (undistorted pixels)");
  cmd->add_option("--model", opt->model_path, "Wireframe model (.cao): its dominant directions")
      ->required();
  cmd->add_option("--tilt", opt->tilt_deg, "Known tilt (degrees, positive down); else estimated");
  cmd->add_flag("--json", opt->json, "Print the result as JSON");
  AddLineFlags(cmd, &opt->lines);
  cmd->get_option("--camera")->required();
  cmd->callback([opt, action] { *action = [opt] { return RunHeading(*opt); }; });
}

}  // namespace linetrack::app
