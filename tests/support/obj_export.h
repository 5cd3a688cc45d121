// Support for the import tests: a .cao model exported as a modeller would give it, an OBJ
// triangle mesh in millimetres with y up.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "models/cao_reader.h"

namespace linetrack::test_support {

// `cao` as OBJ text: faces fan-triangulated (convex faces), 3D lines as `l` elements, points in
// millimetres with y up ((x, y, z) -> 1000 (x, z, -y)).
inline std::string ObjMillimetresYUp(const CaoModel& cao) {
  std::ostringstream obj;
  obj.precision(12);
  for (const Eigen::Vector3d& p : cao.points)
    obj << "v " << 1e3 * p.x() << " " << 1e3 * p.z() << " " << -1e3 * p.y() << "\n";
  for (const std::vector<int>& face : cao.faces) {
    for (size_t k = 1; k + 1 < face.size(); ++k)
      obj << "f " << face[0] + 1 << " " << face[k] + 1 << " " << face[k + 1] + 1 << "\n";
  }
  for (const std::array<int, 2>& line : cao.lines)
    obj << "l " << line[0] + 1 << " " << line[1] + 1 << "\n";
  return obj.str();
}

}  // namespace linetrack::test_support
