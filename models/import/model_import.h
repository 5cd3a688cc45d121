// Building models as users have them (IFC, DXF, OBJ, PLY, STL, glTF/GLB, Collada, FBX, 3DS, X3D)
// read through Assimp and turned into the .cao wireframe linetrack reads (MeshToCao): in metres,
// z up.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "models/cao_reader.h"
#include "models/import/mesh_to_cao.h"

namespace linetrack {

enum class UpAxis { kY, kZ };

struct ModelImportOptions {
  // Metres per unit of the file, for formats that do not state their unit (all but glTF, which is
  // in metres, and IFC, whose units Assimp applies); nullopt: metres.
  std::optional<double> metres_per_unit;
  // The file's up axis; nullopt: the format's (y for OBJ, glTF, FBX, X3D; else z). Ignored for
  // the formats Assimp turns itself (AssimpTurnsYUp).
  std::optional<UpAxis> up;
  MeshToCaoOptions mesh;

  bool Check(std::string* why) const;
};

// The imported model and what was done to it.
struct ImportedModel {
  CaoModel cao;
  MeshToCaoSummary summary;
  double metres_per_unit = 1.0;       // the scale applied
  UpAxis up = UpAxis::kZ;             // the up axis the file was read with
  std::vector<std::string> notes;     // decisions the user should know (unit, up axis)
  std::vector<std::string> warnings;  // likely problems (an implausible extent)
};

// True for the formats whose up axis Assimp reads and turns to y itself (IFC and DXF: z up;
// Collada: its <up_axis>); --up does not apply to them.
bool AssimpTurnsYUp(const std::string& path);

// The up axis of the meshes Assimp gives for `path` (by its extension) when the user gives none.
UpAxis DefaultUpAxis(const std::string& path);

// True when the format of `path` states its unit (glTF/GLB: metres; IFC: its own units).
bool FormatStatesUnit(const std::string& path);

// Reads `path` through Assimp and converts it. Throws InputError naming the file when Assimp
// cannot read it, it holds no triangle or line, or the options are invalid.
ImportedModel ImportModel(const std::string& path, const ModelImportOptions& options);

}  // namespace linetrack
