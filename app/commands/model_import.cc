// `linetrack model-import IN --out OUT.cao [--unit mm|cm|m] [--up z|y] [--feature-angle DEG]
// [--merge-tolerance M]`: a CAD or BIM model (IFC, DXF, OBJ, PLY, STL, glTF, ...) through Assimp
// to the .cao wireframe linetrack reads (models/import/model_import.h).
#include <spdlog/spdlog.h>

#include <iostream>
#include <map>
#include <memory>

#include "app/commands.h"
#include "models/cao_writer.h"
#include "models/errors.h"
#include "models/import/model_import.h"
#include "models/wireframe.h"

namespace linetrack::app {
namespace {

struct ModelImportCliOptions {
  std::string in_path;
  std::string out_path;
  std::string unit;  // "" (the format's), mm, cm or m
  std::string up;    // "" (the format's), y or z
  ModelImportOptions import;
};

// The summary of what the import did, one line a topic.
void PrintSummary(const ImportedModel& model, const std::string& out_path) {
  const MeshToCaoSummary& s = model.summary;
  const WireframeModel wireframe = WireframeModel::FromCao(model.cao);
  int vertical = 0;
  for (const ModelEdge& edge : wireframe.edges())
    vertical += edge.vertical ? 1 : 0;
  std::cout << "wrote " << out_path << ": " << model.cao.points.size() << " points, " << s.faces
            << " faces, " << s.lines << " 3D lines, " << wireframe.edges().size() << " edges ("
            << vertical << " vertical)\n"
            << "read: " << s.input_points << " points, " << s.input_triangles << " triangles, "
            << s.input_lines << " lines\n"
            << "feature edges: " << s.feature_edges << "; dropped: " << s.tessellation_edges
            << " tessellation edges, " << s.curved_facets << " facets of curved surfaces, "
            << s.degenerate_triangles << " degenerate triangles\n"
            << "merged: " << s.merged_triangles << " triangles into faces, " << s.welded_points
            << " points welded, " << s.collinear_points << " collinear points\n"
            << "doors and windows as lines: " << s.openings << "; holes as lines: " << s.holes
            << "\n";
  for (const std::string& note : model.notes)
    std::cout << "note: " << note << "\n";
  std::cout << std::flush;
}

int RunModelImport(ModelImportCliOptions opt) {
  static const std::map<std::string, double> kUnits = {{"mm", 1e-3}, {"cm", 1e-2}, {"m", 1.0}};
  if (!opt.unit.empty()) opt.import.metres_per_unit = kUnits.at(opt.unit);
  if (!opt.up.empty()) opt.import.up = opt.up == "y" ? UpAxis::kY : UpAxis::kZ;
  const ImportedModel model = ImportModel(opt.in_path, opt.import);
  for (const std::string& warning : model.warnings)
    spdlog::warn("{}: {}", opt.in_path, warning);
  WriteFileAtomically(opt.out_path,
                      CaoText(model.cao, "imported from " + opt.in_path +
                                             " by `linetrack model-import`; metres, z up"));
  PrintSummary(model, opt.out_path);
  return kExitOk;
}

}  // namespace

void AddModelImport(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<ModelImportCliOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "model-import",
      "Converts a CAD or BIM model (IFC, DXF, OBJ, PLY, STL, glTF/GLB, Collada, FBX, 3DS, X3D) "
      "into a .cao wireframe: feature edges, coplanar triangles merged into faces, metres, z up");
  cmd->add_option("in", opt->in_path, "Input model file")->required();
  cmd->add_option("--out", opt->out_path, "Output .cao file")->required();
  cmd->add_option("--unit", opt->unit,
                  "Unit of a file that does not state one (glTF and IFC do): mm, cm or m "
                  "(default m)")
      ->check(CLI::IsMember({"mm", "cm", "m"}));
  cmd->add_option("--up", opt->up, "Up axis of the file (default: the format's; y for OBJ, glTF)")
      ->check(CLI::IsMember({"y", "z"}));
  cmd->add_option("--feature-angle", opt->import.mesh.feature_angle_deg,
                  "Faces meeting at more than this angle (degrees) make a feature edge")
      ->capture_default_str();
  cmd->add_option("--merge-tolerance", opt->import.mesh.merge_tolerance,
                  "Vertices closer than this (metres) are welded; collinear within it merged")
      ->capture_default_str();
  cmd->callback([opt, action] { *action = [opt] { return RunModelImport(*opt); }; });
}

}  // namespace linetrack::app
