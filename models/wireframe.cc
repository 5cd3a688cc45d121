#include "models/wireframe.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "models/errors.h"
#include "models/face_orientation.h"
#include "models/free_space.h"

namespace linetrack {
namespace {

// Merges points closer than `radius` into one vertex (hash grid with neighbour lookup).
class VertexMerger {
 public:
  explicit VertexMerger(double radius) : radius_(radius), cell_(std::max(radius, 1e-12) * 4.0) {}

  int Add(const Eigen::Vector3d& p, std::vector<Eigen::Vector3d>* vertices) {
    const Key key = KeyOf(p);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it =
              grid_.find(Key{std::get<0>(key) + dx, std::get<1>(key) + dy, std::get<2>(key) + dz});
          if (it == grid_.end()) continue;
          for (int id : it->second) {
            if (((*vertices)[id] - p).norm() <= radius_) return id;
          }
        }
      }
    }
    const int id = static_cast<int>(vertices->size());
    vertices->push_back(p);
    grid_[key].push_back(id);
    return id;
  }

 private:
  using Key = std::tuple<long long, long long, long long>;
  Key KeyOf(const Eigen::Vector3d& p) const {
    return {static_cast<long long>(std::floor(p.x() / cell_)),
            static_cast<long long>(std::floor(p.y() / cell_)),
            static_cast<long long>(std::floor(p.z() / cell_))};
  }
  double radius_;
  double cell_;
  std::map<Key, std::vector<int>> grid_;
};

// Newell's method: robust normal of a (possibly non-convex) planar polygon.
Eigen::Vector3d NewellNormal(const std::vector<Eigen::Vector3d>& corners) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < corners.size(); ++i) {
    const Eigen::Vector3d& a = corners[i];
    const Eigen::Vector3d& b = corners[(i + 1) % corners.size()];
    n.x() += (a.y() - b.y()) * (a.z() + b.z());
    n.y() += (a.z() - b.z()) * (a.x() + b.x());
    n.z() += (a.x() - b.x()) * (a.y() + b.y());
  }
  return n;
}

// The face through `vertices` (ids into `all`), its plane from Newell's normal; a zero normal
// when the polygon has no area.
ModelFace MakeFace(const std::vector<int>& vertices, const std::vector<Eigen::Vector3d>& all,
                   const std::string& name) {
  ModelFace face;
  face.name = name;
  face.vertices = vertices;
  for (int v : vertices)
    face.corners.push_back(all[v]);
  const Eigen::Vector3d n = NewellNormal(face.corners);
  double extent = 0.0;
  for (const Eigen::Vector3d& c : face.corners)
    extent = std::max(extent, (c - face.corners[0]).norm());
  if (n.norm() > 1e-9 * std::max(1.0, extent * extent)) {
    face.normal = n.normalized();
    face.offset = face.normal.dot(face.corners[0]);
    face.vertical = std::abs(face.normal.z()) < 1e-6;
    face.horizontal = std::abs(std::abs(face.normal.z()) - 1.0) < 1e-9;
  }
  return face;
}

// names[i], or "" when the list is shorter (a CaoModel built without names).
std::string NameAt(const std::vector<std::string>& names, size_t i) {
  return i < names.size() ? names[i] : std::string();
}

// The distinct non-empty names, in order, joined by '/'.
std::string JoinedNames(const std::vector<std::string>& names) {
  std::string joined;
  std::vector<std::string> seen;
  for (const std::string& name : names) {
    if (name.empty() || std::find(seen.begin(), seen.end(), name) != seen.end()) continue;
    seen.push_back(name);
    joined += (joined.empty() ? "" : "/") + name;
  }
  return joined;
}

// The faces of `cao` on the merged vertices, with their planes and names; counts those without
// area.
std::vector<ModelFace> BuildFaces(const CaoModel& cao, const std::vector<int>& vertex_of_point,
                                  const std::vector<Eigen::Vector3d>& vertices, int* degenerate) {
  std::vector<ModelFace> faces;
  for (size_t f = 0; f < cao.faces.size(); ++f) {
    std::vector<int> ids;
    for (int p : cao.faces[f])
      ids.push_back(vertex_of_point[p]);
    faces.push_back(MakeFace(ids, vertices, NameAt(cao.face_names, f)));
    *degenerate += faces.back().Degenerate() ? 1 : 0;
  }
  return faces;
}

void Flip(ModelFace* face) {
  std::reverse(face->vertices.begin(), face->vertices.end());
  std::reverse(face->corners.begin(), face->corners.end());
  face->normal = -face->normal;
  face->offset = -face->offset;
  face->flipped = !face->flipped;
}

}  // namespace

bool WireframeOptions::Check(std::string* why) const {
  if (!(vertical_tolerance_deg > 0.0 && vertical_tolerance_deg < 45.0)) {
    *why = "vertical_tolerance_deg must be in (0, 45)";
    return false;
  }
  if (!(merge_distance >= 0.0 && merge_distance < 0.01)) {
    *why = "merge_distance must be in [0, 0.01) metres";
    return false;
  }
  return true;
}

WireframeModel WireframeModel::FromCao(const CaoModel& cao, const WireframeOptions& options) {
  WireframeModel model;
  model.path_ = cao.files.empty() ? std::string("<memory>") : cao.files.front();
  std::string why;
  if (!options.Check(&why)) throw InputError(Located(model.path_, 0, why));
  model.warnings_ = cao.warnings;
  model.num_points_ = static_cast<int>(cao.points.size());
  model.num_lines_ = static_cast<int>(cao.lines.size());

  VertexMerger merger(options.merge_distance);
  std::vector<int> vertex_of_point(cao.points.size());
  for (size_t i = 0; i < cao.points.size(); ++i) {
    vertex_of_point[i] = merger.Add(cao.points[i], &model.vertices_);
  }
  if (!model.vertices_.empty()) {
    model.box_min_ = model.box_max_ = model.vertices_.front();
    for (const Eigen::Vector3d& v : model.vertices_) {
      model.box_min_ = model.box_min_.cwiseMin(v);
      model.box_max_ = model.box_max_.cwiseMax(v);
    }
  }

  int degenerate_faces = 0;
  model.faces_ = BuildFaces(cao, vertex_of_point, model.vertices_, &degenerate_faces);
  model.storeys_ = DetectStoreys(model.faces_, model.box_min_.z(), model.box_max_.z());
  if (options.orient_faces) {
    const std::vector<FaceOrientation> orientation = OrientFaces(model);
    model.oriented_ = !orientation.empty();
    for (size_t f = 0; f < orientation.size(); ++f) {
      if (orientation[f].flip) Flip(&model.faces_[f]);
      model.faces_[f].two_sided = orientation[f].rule == OrientationRule::kTwoSided;
      model.faces_[f].one_sided = orientation[f].rule == OrientationRule::kFreeSide ||
                                  orientation[f].rule == OrientationRule::kOutsideSide;
    }
    model.orientation_summary_ = OrientationSummary(model, orientation);
  }

  // Edges after orientation: a face's edges are numbered in its (oriented) point order.
  const double cos_vertical = std::cos(DegToRad(options.vertical_tolerance_deg));
  std::map<std::pair<int, int>, int> edge_of_vertices;
  int degenerate = 0;
  std::vector<std::vector<std::string>> face_names_of_edge;  // per edge, the named faces it borders
  auto add_edge = [&](int v0, int v1, bool from_line, int face, const std::string& name) {
    if (v0 == v1) {
      ++degenerate;
      return;
    }
    const auto key = std::minmax(v0, v1);
    if (const auto known = edge_of_vertices.find(key); known != edge_of_vertices.end()) {
      if (face >= 0) face_names_of_edge[known->second].push_back(name);
      return;
    }
    ModelEdge edge;
    edge.id = static_cast<int>(model.edges_.size());
    edge.v0 = v0;
    edge.v1 = v1;
    edge.segment = {model.vertices_[v0], model.vertices_[v1]};
    edge.vertical = std::abs(edge.segment.Direction().z()) >= cos_vertical;
    edge.from_line = from_line;
    edge.face = face;
    if (from_line) edge.name = name;
    edge_of_vertices[key] = edge.id;
    model.edges_.push_back(edge);
    face_names_of_edge.emplace_back();
    if (face >= 0) face_names_of_edge.back().push_back(name);
  };
  for (size_t l = 0; l < cao.lines.size(); ++l) {
    add_edge(vertex_of_point[cao.lines[l][0]], vertex_of_point[cao.lines[l][1]], true, -1,
             NameAt(cao.line_names, l));
  }
  for (size_t f = 0; f < model.faces_.size(); ++f) {
    const std::vector<int>& face = model.faces_[f].vertices;
    for (size_t i = 0; i < face.size(); ++i) {
      add_edge(face[i], face[(i + 1) % face.size()], false, static_cast<int>(f),
               model.faces_[f].name);
    }
  }
  for (ModelEdge& edge : model.edges_) {
    if (edge.name.empty()) edge.name = JoinedNames(face_names_of_edge[edge.id]);
  }
  if (degenerate > 0) {
    model.warnings_.push_back(
        Located(model.path_, 0, std::to_string(degenerate) + " zero-length edges skipped"));
  }
  if (degenerate_faces > 0) {
    model.warnings_.push_back(
        Located(model.path_, 0,
                std::to_string(degenerate_faces) + " faces without area (ignored as occluders)"));
  }
  return model;
}

WireframeModel WireframeModel::Load(const std::string& path, const WireframeOptions& options) {
  return FromCao(ReadCao(path), options);
}

int WireframeModel::NumVerticalEdges() const {
  int n = 0;
  for (const ModelEdge& e : edges_)
    n += e.vertical ? 1 : 0;
  return n;
}

}  // namespace linetrack
