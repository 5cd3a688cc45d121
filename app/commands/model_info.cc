// `linetrack model-info MODEL.cao [--json]`: what the model holds and what the matcher will use.
#include <spdlog/spdlog.h>

#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/commands.h"
#include "models/navigable_area.h"
#include "models/view_invariant_regions.h"
#include "models/wireframe.h"

namespace linetrack::app {
namespace {

struct ModelInfoOptions {
  std::string model_path;
  std::string sidecar_path;
  double clearance = NavigableAreaOptions().clearance;
  double vertical_tolerance_deg = WireframeOptions().vertical_tolerance_deg;
  bool json = false;
};

nlohmann::json Point(const Eigen::Vector3d& p) {
  return {p.x(), p.y(), p.z()};
}

int RunModelInfo(const ModelInfoOptions& opt) {
  WireframeOptions wire_options;
  wire_options.vertical_tolerance_deg = opt.vertical_tolerance_deg;
  const WireframeModel model = WireframeModel::Load(opt.model_path, wire_options);
  for (const std::string& w : model.warnings())
    spdlog::warn("{}", w);
  NavigableAreaOptions area_options;
  area_options.clearance = opt.clearance;
  area_options.sidecar_path = opt.sidecar_path;
  const NavigableArea area = NavigableArea::FromModel(model, area_options);
  const ViewInvariantRegions regions = ViewInvariantRegions::Build(model, area);

  int face_edges = 0;
  for (const ModelEdge& e : model.edges())
    face_edges += e.from_line ? 0 : 1;
  nlohmann::json info = {
      {"model", model.path()},
      {"points", model.num_points()},
      {"vertices", static_cast<int>(model.vertices().size())},
      {"lines", model.num_lines()},
      {"edges", static_cast<int>(model.edges().size())},
      {"edges_from_faces", face_edges},
      {"vertical_edges", model.NumVerticalEdges()},
      {"faces", static_cast<int>(model.faces().size())},
      {"bounding_box", {{"min", Point(model.BoxMin())}, {"max", Point(model.BoxMax())}}},
      {"navigable_area",
       {{"source", area.source()},
        {"area_m2", area.Area()},
        {"outer_vertices", static_cast<int>(area.outer().vertices.size())},
        {"holes", static_cast<int>(area.holes().size())},
        {"clearance_m", area.clearance()}}},
      {"view_invariant_regions", regions.size()},
      {"warnings", model.warnings()},
  };
  if (opt.json) {
    std::cout << info.dump(2) << std::endl;
    return kExitOk;
  }
  std::ostringstream out;
  out << std::fixed << std::setprecision(2);
  const Eigen::Vector3d lo = model.BoxMin(), hi = model.BoxMax();
  out << "model                  " << model.path() << "\n"
      << "points                 " << model.num_points() << " (" << model.vertices().size()
      << " distinct vertices)\n"
      << "edges                  " << model.edges().size() << " (" << model.num_lines()
      << " 3D lines, " << face_edges << " more from faces)\n"
      << "vertical edges         " << model.NumVerticalEdges() << "\n"
      << "faces                  " << model.faces().size() << "\n"
      << "bounding box (m)       x " << lo.x() << " .. " << hi.x() << ", y " << lo.y() << " .. "
      << hi.y() << ", z " << lo.z() << " .. " << hi.z() << "\n"
      << "navigable area         " << area.Area() << " m2 from " << area.source() << ", "
      << area.outer().vertices.size() << " vertices, " << area.holes().size()
      << " obstacles, clearance " << area.clearance() << " m\n"
      << "view-invariant regions " << regions.size() << "\n";
  std::cout << out.str();
  return kExitOk;
}

}  // namespace

void AddModelInfo(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<ModelInfoOptions>();
  CLI::App* cmd =
      cli.add_subcommand("model-info",
                         "Counts of points, edges, vertical edges and faces, the bounding box, the "
                         "navigable area and the number of view-invariant regions of a .cao model");
  cmd->add_option("model", opt->model_path, "ViSP .cao model file")->required();
  cmd->add_flag("--json", opt->json, "Print one JSON object instead of a table");
  cmd->add_option("--nav", opt->sidecar_path,
                  "Navigable-area polygon file (default: MODEL.nav.json next to the model when "
                  "it exists, else derived from the walls)");
  cmd->add_option("--clearance", opt->clearance,
                  "Minimum distance of the camera from walls and obstacles (metres)")
      ->capture_default_str();
  cmd->add_option("--vertical-tolerance", opt->vertical_tolerance_deg,
                  "Largest angle to the z axis of a vertical edge (degrees)")
      ->capture_default_str();
  cmd->callback([opt, action] { *action = [opt] { return RunModelInfo(*opt); }; });
}

}  // namespace linetrack::app
