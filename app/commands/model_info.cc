// `linetrack model-info MODEL.cao [--json]`: what the model holds and what the matcher will use.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <random>
#include <sstream>

#include "app/commands.h"
#include "app/model_loading.h"
#include "models/camera.h"
#include "models/geometry.h"
#include "models/navigable_area.h"
#include "models/statistics.h"
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
  bool edges = false;  // list every edge with its name and end points
  // Benchmark of the VIR query: random priors in the navigable area (0: none).
  int queries = 0;
  double query_radius = 0.5;       // delta_t, metres (the paper's QI2)
  double query_margin_deg = 15.0;  // delta_phi, degrees
};

// Figures of the VIR query over seeded random priors, for the paper's synthetic camera
// (640x480 px, f = 1000 px) at tilts 0..20 degrees.
struct QueryStats {
  double mean_kept = 0.0;
  double selectivity = 0.0;  // mean kept / edge count
  double mean_us = 0.0;
  double median_us = 0.0;
};

QueryStats BenchmarkQueries(const ViewInvariantRegions& regions, const NavigableArea& area,
                            int num_edges, const ModelInfoOptions& opt) {
  CameraIntrinsics camera;
  camera.width = 640;
  camera.height = 480;
  camera.px = camera.py = 1000.0;
  camera.u0 = 320.0;
  camera.v0 = 240.0;
  const double half_width = BearingHalfWidth(camera, 0.0, DegToRad(20.0));
  std::mt19937 rng(1u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector2d lo = area.BoundsMin(), size = area.BoundsMax() - lo;
  std::vector<double> times_us;
  double kept = 0.0;
  for (int i = 0; i < opt.queries; ++i) {
    VisibilityQuery query;
    do {
      query.centre = lo + Eigen::Vector2d(unit(rng) * size.x(), unit(rng) * size.y());
    } while (!area.Contains(query.centre));
    query.radius = opt.query_radius;
    query.heading = kPi * (2.0 * unit(rng) - 1.0);
    query.heading_margin = DegToRad(opt.query_margin_deg);
    query.bearing_half_width = half_width;
    const auto start = std::chrono::steady_clock::now();
    kept += static_cast<double>(regions.Query(query).size());
    times_us.push_back(
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
            .count());
  }
  QueryStats stats;
  if (times_us.empty()) return stats;
  stats.mean_kept = kept / opt.queries;
  stats.selectivity = stats.mean_kept / std::max(1, num_edges);
  stats.mean_us = std::accumulate(times_us.begin(), times_us.end(), 0.0) / times_us.size();
  stats.median_us = QuantileNearestRank(times_us, 0.5);
  return stats;
}

nlohmann::json Point(const Eigen::Vector3d& p) {
  return {p.x(), p.y(), p.z()};
}

int NumHoles(const NavigableArea& area) {
  int n = 0;
  for (const AreaPart& part : area.parts())
    n += static_cast<int>(part.holes.size());
  return n;
}

nlohmann::json Storeys(const WireframeModel& model, const NavigableArea& area) {
  nlohmann::json out = nlohmann::json::array();
  for (size_t s = 0; s < model.storeys().size(); ++s) {
    out.push_back({{"floor_z", model.storeys()[s].floor_z},
                   {"top_z", model.storeys()[s].top_z},
                   {"area_m2", area.Area(static_cast<int>(s))}});
  }
  return out;
}

std::vector<std::string> FindingMessages(const std::vector<ModelFinding>& findings) {
  std::vector<std::string> out;
  for (const ModelFinding& finding : findings)
    out.push_back(finding.message);
  return out;
}

// What orienting the faces did, one sentence a line.
std::string OrientationLines(const WireframeModel& model) {
  if (!model.oriented()) return "faces as written (no enclosed free space: an object)";
  if (model.orientation_summary().empty()) return "every face already faces the free space";
  std::string text;
  for (const std::string& line : model.orientation_summary())
    text += (text.empty() ? "" : "\n                       ") + line;
  return text;
}

// The text table's rows about the model itself: counts, box, area and storeys, orientation,
// the checks' findings.
std::string ModelTable(const WireframeModel& model, const NavigableArea& area,
                       const std::vector<ModelFinding>& findings, int face_edges) {
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
      << area.parts().size() << (area.parts().size() == 1 ? " part, " : " parts, ")
      << NumHoles(area) << " obstacles, clearance " << area.clearance() << " m\n";
  if (model.storeys().size() > 1) {
    for (size_t s = 0; s < model.storeys().size(); ++s) {
      out << "storey " << s << "                floor z " << model.storeys()[s].floor_z
          << " m, walls to " << model.storeys()[s].top_z << " m, " << area.Area(static_cast<int>(s))
          << " m2\n";
    }
  }
  out << "orientation            " << OrientationLines(model) << "\n";
  out << "checks                 "
      << (findings.empty()
              ? "nothing found"
              : std::to_string(findings.size()) + (findings.size() == 1 ? " finding" : " findings"))
      << "\n";
  for (const ModelFinding& finding : findings)
    out << "  " << finding.message << "\n";
  return out.str();
}

// Every edge: id, name, end points (metres) and whether it is vertical.
nlohmann::json EdgeListJson(const WireframeModel& model) {
  nlohmann::json list = nlohmann::json::array();
  for (const ModelEdge& e : model.edges()) {
    list.push_back({{"id", e.id},
                    {"name", e.name},
                    {"from", Point(e.segment.a)},
                    {"to", Point(e.segment.b)},
                    {"vertical", e.vertical}});
  }
  return list;
}

// "(x, y, z)" in metres, two decimals.
std::string PointText(const Eigen::Vector3d& p) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(2) << "(" << p.x() << ", " << p.y() << ", " << p.z()
       << ")";
  return text.str();
}

// The same as a table, one edge a line: id, name ("-" without one), end points, "vertical".
std::string EdgeListText(const WireframeModel& model) {
  size_t width = 4;
  for (const ModelEdge& e : model.edges())
    width = std::max(width, e.name.size());
  constexpr int kPointWidth = 23;  // "(-100.00, -100.00, 10.00)" fits, aligned below
  std::ostringstream out;
  out << "\n  id  " << std::left << std::setw(width) << "name"
      << "  from (m)                 to (m)\n";
  for (const ModelEdge& e : model.edges()) {
    out << std::right << std::setw(4) << e.id << "  " << std::left << std::setw(width)
        << (e.name.empty() ? "-" : e.name) << "  " << std::setw(kPointWidth)
        << PointText(e.segment.a) << "  ";
    if (e.vertical) {
      out << std::setw(kPointWidth) << PointText(e.segment.b) << "  vertical\n";
    } else {
      out << PointText(e.segment.b) << "\n";
    }
  }
  return out.str();
}

int RunModelInfo(const ModelInfoOptions& opt) {
  WireframeOptions wire_options;
  wire_options.vertical_tolerance_deg = opt.vertical_tolerance_deg;
  const WireframeModel model = WireframeModel::Load(opt.model_path, wire_options);
  const std::vector<ModelFinding> findings = ReportModel(model);
  NavigableAreaOptions area_options;
  area_options.clearance = opt.clearance;
  area_options.sidecar_path = opt.sidecar_path;
  const NavigableArea area = NavigableArea::FromModel(model, area_options);
  const auto build_start = std::chrono::steady_clock::now();
  const ViewInvariantRegions regions = ViewInvariantRegions::Build(model, area);
  const double build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - build_start)
          .count();
  const QueryStats stats =
      BenchmarkQueries(regions, area, static_cast<int>(model.edges().size()), opt);

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
        {"parts", static_cast<int>(area.parts().size())},
        {"holes", NumHoles(area)},
        {"clearance_m", area.clearance()}}},
      {"storeys", Storeys(model, area)},
      {"orientation", model.orientation_summary()},
      {"view_invariant_regions", regions.size()},
      {"view_invariant_regions_build_ms", build_ms},
      {"warnings", model.warnings()},
      {"findings", FindingMessages(findings)},
  };
  if (opt.queries > 0) {
    info["vir_queries"] = {{"count", opt.queries},
                           {"radius_m", opt.query_radius},
                           {"heading_margin_deg", opt.query_margin_deg},
                           {"mean_edges_kept", stats.mean_kept},
                           {"selectivity", stats.selectivity},
                           {"mean_us", stats.mean_us},
                           {"median_us", stats.median_us}};
  }
  if (opt.edges) info["edge_list"] = EdgeListJson(model);
  if (opt.json) {
    std::cout << info.dump(2) << std::endl;
    return kExitOk;
  }
  std::ostringstream out;
  out << std::fixed << std::setprecision(2);
  out << ModelTable(model, area, findings, face_edges);
  out << "view-invariant regions " << regions.size() << " (built in " << build_ms << " ms; "
      << regions.occluders().size() << " occluding wall segments, " << regions.solids().size()
      << " solid obstacles)\n";
  if (opt.queries > 0) {
    out << "VIR queries            " << opt.queries << " random priors (" << opt.query_radius
        << " m, " << opt.query_margin_deg
        << " deg; 640x480 px, f 1000 px, tilt 0..20 deg): " << stats.mean_kept << " of "
        << model.edges().size() << " edges kept (selectivity " << std::setprecision(3)
        << stats.selectivity << std::setprecision(2) << "), " << stats.mean_us << " us mean, "
        << stats.median_us << " us median\n";
  }
  if (opt.edges) out << EdgeListText(model);
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
  cmd->add_flag("--edges", opt->edges,
                "Also list every edge: its id (as localize reports matches), its name (the .cao "
                "name= of its line, else of the faces it borders) and end points");
  cmd->add_option("--nav", opt->sidecar_path,
                  "Navigable-area polygon file (default: MODEL.nav.json next to the model when "
                  "it exists, else derived from the walls)");
  cmd->add_option("--clearance", opt->clearance,
                  "Minimum distance of the camera from walls and obstacles (metres)")
      ->capture_default_str();
  cmd->add_option("--vertical-tolerance", opt->vertical_tolerance_deg,
                  "Largest angle to the z axis of a vertical edge (degrees)")
      ->capture_default_str();
  cmd->add_option("--queries", opt->queries,
                  "Also time this many random VIR queries in the navigable area and report the "
                  "mean fraction of edges kept")
      ->check(CLI::Range(0, 10000000))
      ->capture_default_str();
  cmd->add_option("--query-radius", opt->query_radius, "Prior disk radius delta_t (metres)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  cmd->add_option("--query-margin", opt->query_margin_deg,
                  "Prior heading margin delta_phi (degrees)")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  cmd->callback([opt, action, cmd] {
    RefuseUnless(*cmd, opt->queries > 0, {"--query-radius", "--query-margin"},
                 "applies to the VIR queries of --queries N");
    *action = [opt] { return RunModelInfo(*opt); };
  });
}

}  // namespace linetrack::app
