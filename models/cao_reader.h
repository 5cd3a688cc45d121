// Reader for ViSP's .cao wireframe format (V1), as vpMbTracker::loadCAOModel reads it:
// optional "V1" header, load("file.cao"[, t=[..], tu=[..]]) includes, then the sections
// points, 3D lines, faces from lines, faces from points, cylinders, circles.
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace linetrack {

// The raw content of a .cao file and its includes, with indices made global (included files
// first, in the order ViSP loads them). Faces from lines are turned into point loops.
struct CaoModel {
  std::vector<Eigen::Vector3d> points;    // metres, in the model (world) frame
  std::vector<std::array<int, 2>> lines;  // indices into points
  std::vector<std::vector<int>> faces;    // closed polygons as indices into points
  // The name="..." parameter of each line and face (parallel to lines and faces; "" without).
  std::vector<std::string> line_names, face_names;
  std::vector<std::string> warnings;  // e.g. cylinders and circles ignored
  std::vector<std::string> files;     // every file read, the top one first
};

// Reads the content of an included file: returns nullopt when it cannot be read.
using CaoIncludeReader = std::function<std::optional<std::string>(const std::string& path)>;

// Parses .cao text. `path` names the file in error messages and resolves relative includes;
// `read_include` reads included files (nullptr: includes are an error). Throws InputError
// ("path:line: what") on any malformed content; never reads past the text.
CaoModel ParseCao(const std::string& text, const std::string& path,
                  const CaoIncludeReader& read_include);

// Reads a .cao file from disk, includes resolved relative to the including file.
// Throws InputError naming the file and line at fault.
CaoModel ReadCao(const std::string& path);

}  // namespace linetrack
