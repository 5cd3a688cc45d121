#include "models/import/model_import.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "models/errors.h"
#include "models/import/import_guards.h"

namespace linetrack {
namespace {

// A model wider than this (metres) is almost certainly in millimetres read as metres.
constexpr double kImplausibleExtentM = 1000.0;
// More vertices than this are refused (the indices are ints).
constexpr size_t kMaxImportPoints = size_t{1} << 30;

std::string Extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// The triangles and lines of every mesh of the scene, node transforms applied (Assimp's
// aiProcess_PreTransformVertices), scaled to metres and rotated to z up.
ImportMesh MeshOfScene(const aiScene& scene, double scale, UpAxis up, const std::string& path) {
  ImportMesh mesh;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& in = *scene.mMeshes[m];
    if (in.mNumVertices > kMaxImportPoints - mesh.points.size())
      throw InputError(Located(path, 0, "over 2^30 vertices"));
    const int base = static_cast<int>(mesh.points.size());
    for (unsigned v = 0; v < in.mNumVertices; ++v) {
      const aiVector3D& p = in.mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw InputError(Located(path, 0, "a vertex coordinate is not a finite number"));
      // y up: (x, y, z) -> (x, -z, y), a rotation of +90 degrees about x.
      const Eigen::Vector3d q =
          up == UpAxis::kY ? Eigen::Vector3d(p.x, -p.z, p.y) : Eigen::Vector3d(p.x, p.y, p.z);
      mesh.points.push_back(scale * q);
    }
    for (unsigned f = 0; f < in.mNumFaces; ++f) {
      const aiFace& face = in.mFaces[f];
      for (unsigned k = 0; k < face.mNumIndices; ++k) {
        if (face.mIndices[k] >= in.mNumVertices)
          throw InputError(Located(path, 0, "a face refers to a vertex the file does not hold"));
      }
      if (face.mNumIndices == 3) {
        mesh.triangles.push_back({base + static_cast<int>(face.mIndices[0]),
                                  base + static_cast<int>(face.mIndices[1]),
                                  base + static_cast<int>(face.mIndices[2])});
      } else if (face.mNumIndices == 2) {
        mesh.lines.push_back(
            {base + static_cast<int>(face.mIndices[0]), base + static_cast<int>(face.mIndices[1])});
      }
    }
  }
  return mesh;
}

std::string Metres(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace

bool ModelImportOptions::Check(std::string* why) const {
  if (metres_per_unit && !(*metres_per_unit > 0.0 && std::isfinite(*metres_per_unit))) {
    *why = "the unit must be a positive number of metres";
    return false;
  }
  return mesh.Check(why);
}

bool AssimpTurnsYUp(const std::string& path) {
  const std::string ext = Extension(path);
  return ext == ".ifc" || ext == ".dxf" || ext == ".dae";
}

UpAxis DefaultUpAxis(const std::string& path) {
  const std::string ext = Extension(path);
  if (AssimpTurnsYUp(path)) return UpAxis::kY;
  for (const char* y_up : {".obj", ".gltf", ".glb", ".fbx", ".x3d"}) {
    if (ext == y_up) return UpAxis::kY;
  }
  return UpAxis::kZ;
}

bool FormatStatesUnit(const std::string& path) {
  const std::string ext = Extension(path);
  return ext == ".gltf" || ext == ".glb" || ext == ".ifc";
}

ImportedModel ImportModel(const std::string& path, const ModelImportOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError(Located(path, 0, why));
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(Located(path, 0, "cannot read the model file"));
  ImportedModel model;
  if (AssimpTurnsYUp(path)) {
    model.up = UpAxis::kY;
    model.notes.push_back(std::string("up axis: read from the file by Assimp") +
                          (options.up ? " (--up ignored)" : ""));
  } else {
    model.up = options.up.value_or(DefaultUpAxis(path));
    model.notes.push_back(std::string("up axis ") + (model.up == UpAxis::kY ? "y" : "z") +
                          (options.up ? " (--up)" : " (the format's default)"));
  }
  if (FormatStatesUnit(path)) {
    if (options.metres_per_unit) model.notes.push_back("the file states its unit: --unit ignored");
  } else {
    model.metres_per_unit = options.metres_per_unit.value_or(1.0);
    model.notes.push_back("unit " + Metres(model.metres_per_unit) + " m" +
                          (options.metres_per_unit ? " (--unit)" : " (no unit in the file)"));
  }
  CheckBeforeAssimp(path);
  Assimp::Importer importer;
  // Points and lines are kept (3D lines), polygons triangulated, the scene graph flattened.
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                                  aiProcess_PreTransformVertices | aiProcess_SortByPType);
  if (scene == nullptr) {
    throw InputError(
        Located(path, 0, std::string("cannot import the model: ") + importer.GetErrorString()));
  }
  const ImportMesh mesh = MeshOfScene(*scene, model.metres_per_unit, model.up, path);
  if (mesh.triangles.empty() && mesh.lines.empty())
    throw InputError(Located(path, 0, "the file holds no triangle or line"));
  Eigen::Vector3d lo = mesh.points.front(), hi = lo;
  for (const Eigen::Vector3d& p : mesh.points)
    lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  if ((hi - lo).maxCoeff() > kImplausibleExtentM) {
    model.warnings.push_back("the model is " + Metres((hi - lo).maxCoeff() / 1000.0) +
                             " km wide: almost certainly in millimetres (try --unit mm)");
  }
  model.cao = MeshToCao(mesh, options.mesh, path, &model.summary);
  return model;
}

}  // namespace linetrack
