#include "models/cao_writer.h"

#include <algorithm>
#include <cstdio>

#include "models/errors.h"

namespace linetrack {
namespace {

// %.17g round-trips every double.
std::string Number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

}  // namespace

std::string CaoText(const CaoModel& cao, const std::string& title) {
  std::string out = "V1\n# " + title + "\n# points\n" + std::to_string(cao.points.size()) + "\n";
  for (const Eigen::Vector3d& p : cao.points)
    out += Number(p.x()) + " " + Number(p.y()) + " " + Number(p.z()) + "\n";
  out += "# lines\n" + std::to_string(cao.lines.size()) + "\n";
  for (const auto& line : cao.lines)
    out += std::to_string(line[0]) + " " + std::to_string(line[1]) + "\n";
  out += "# faces from lines\n0\n# faces from points\n" + std::to_string(cao.faces.size()) + "\n";
  for (const std::vector<int>& face : cao.faces) {
    out += std::to_string(face.size());
    for (int p : face)
      out += " " + std::to_string(p);
    out += "\n";
  }
  out += "# cylinders\n0\n# circles\n0\n";
  return out;
}

CaoModel OrientedCao(const CaoModel& cao, const WireframeModel& model) {
  if (model.faces().size() != cao.faces.size()) {
    throw InputError(Located(model.path(), 0, "the model was not built from this .cao content"));
  }
  CaoModel out = cao;
  std::vector<std::vector<int>> twins;
  for (size_t f = 0; f < out.faces.size(); ++f) {
    const ModelFace& face = model.faces()[f];
    if (face.flipped) std::reverse(out.faces[f].begin(), out.faces[f].end());
    if (face.two_sided) {
      twins.push_back(out.faces[f]);
      std::reverse(twins.back().begin(), twins.back().end());
    }
  }
  out.faces.insert(out.faces.end(), twins.begin(), twins.end());
  return out;
}

}  // namespace linetrack
