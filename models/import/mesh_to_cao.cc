#include "models/import/mesh_to_cao.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack {
namespace {

// Points farther than this from the origin on an axis are refused (metres).
constexpr double kMaxCoordinateM = 1e7;

using Edge = std::pair<int, int>;  // undirected: first < second

Edge Undirected(int a, int b) {
  return {std::min(a, b), std::max(a, b)};
}

// Distance (metres) from p to the segment a-b.
double DistanceToSegment3(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                          const Eigen::Vector3d& b) {
  const Eigen::Vector3d d = b - a;
  const double length2 = d.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((p - a).dot(d) / length2, 0.0, 1.0) : 0.0;
  return (a + t * d - p).norm();
}

struct Triangle {
  std::array<int, 3> v;
  Eigen::Vector3d normal;
};

// A planar patch: coplanar triangles joined across shared edges.
struct Patch {
  std::vector<int> triangles;
  Eigen::Vector3d normal;  // of its first triangle
  double offset = 0.0;     // normal . x on the plane
  std::vector<std::vector<int>> outer, holes;
  bool curved = false;   // facet of a curved surface
  bool opening = false;  // door or window outline on a larger face
  double area = 0.0;
};

struct MeshTopology {
  std::vector<Triangle> triangles;
  std::map<Edge, std::vector<int>> faces_of_edge;  // edge -> triangles
};

MeshTopology Topology(const ImportMesh& mesh, const std::vector<int>& weld, double tolerance,
                      MeshToCaoSummary* summary) {
  MeshTopology topo;
  for (const std::array<int, 3>& t : mesh.triangles) {
    const Triangle tri{{weld[t[0]], weld[t[1]], weld[t[2]]}, Eigen::Vector3d::Zero()};
    const Eigen::Vector3d& a = mesh.points[tri.v[0]];
    const Eigen::Vector3d cross = (mesh.points[tri.v[1]] - a).cross(mesh.points[tri.v[2]] - a);
    // Twice the area over the longest side: the triangle's height.
    const double longest =
        std::max({(mesh.points[tri.v[1]] - a).norm(), (mesh.points[tri.v[2]] - a).norm(),
                  (mesh.points[tri.v[2]] - mesh.points[tri.v[1]]).norm()});
    if (tri.v[0] == tri.v[1] || tri.v[1] == tri.v[2] || tri.v[0] == tri.v[2] ||
        !(cross.norm() > tolerance * longest)) {
      ++summary->degenerate_triangles;
      continue;
    }
    topo.triangles.push_back({tri.v, cross.normalized()});
  }
  for (size_t i = 0; i < topo.triangles.size(); ++i) {
    const std::array<int, 3>& v = topo.triangles[i].v;
    for (int k = 0; k < 3; ++k)
      topo.faces_of_edge[Undirected(v[k], v[(k + 1) % 3])].push_back(static_cast<int>(i));
  }
  return topo;
}

// Grows patches of coplanar triangles across edges shared by exactly two triangles.
std::vector<Patch> GrowPatches(const MeshTopology& topo, const std::vector<Eigen::Vector3d>& points,
                               const MeshToCaoOptions& options, std::vector<int>* patch_of) {
  const double cos_coplanar = std::cos(DegToRad(options.coplanar_angle_deg));
  patch_of->assign(topo.triangles.size(), -1);
  std::vector<Patch> patches;
  for (size_t seed = 0; seed < topo.triangles.size(); ++seed) {
    if ((*patch_of)[seed] >= 0) continue;
    Patch patch;
    patch.normal = topo.triangles[seed].normal;
    patch.offset = patch.normal.dot(points[topo.triangles[seed].v[0]]);
    const int id = static_cast<int>(patches.size());
    std::vector<int> stack = {static_cast<int>(seed)};
    (*patch_of)[seed] = id;
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      patch.triangles.push_back(t);
      const std::array<int, 3>& v = topo.triangles[t].v;
      for (int k = 0; k < 3; ++k) {
        const std::vector<int>& around = topo.faces_of_edge.at(Undirected(v[k], v[(k + 1) % 3]));
        if (around.size() != 2) continue;
        const int other = around[0] == t ? around[1] : around[0];
        if ((*patch_of)[other] >= 0) continue;
        const Triangle& o = topo.triangles[other];
        const bool on_plane = std::all_of(o.v.begin(), o.v.end(), [&](int p) {
          return std::abs(patch.normal.dot(points[p]) - patch.offset) <= options.merge_tolerance;
        });
        if (std::abs(o.normal.dot(patch.normal)) < cos_coplanar || !on_plane) continue;
        (*patch_of)[other] = id;
        stack.push_back(other);
      }
    }
    patches.push_back(std::move(patch));
  }
  return patches;
}

// Signed area of a closed loop about `normal` (right-hand rule).
double LoopArea(const std::vector<int>& loop, const std::vector<Eigen::Vector3d>& points,
                const Eigen::Vector3d& normal) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < loop.size(); ++i)
    sum += points[loop[i]].cross(points[loop[(i + 1) % loop.size()]]);
  return 0.5 * normal.dot(sum);
}

// The boundary loops of a patch: its triangles' sides not shared inside the patch, each triangle
// taken counter-clockwise about the patch's normal, chained end to start.
void BoundaryLoops(const MeshTopology& topo, const std::vector<int>& patch_of, int id,
                   const std::vector<Eigen::Vector3d>& points, Patch* patch) {
  std::multimap<int, int> next;  // directed boundary sides: start -> end
  for (int t : patch->triangles) {
    std::array<int, 3> v = topo.triangles[t].v;
    if (topo.triangles[t].normal.dot(patch->normal) < 0.0) std::swap(v[1], v[2]);
    for (int k = 0; k < 3; ++k) {
      const std::vector<int>& around = topo.faces_of_edge.at(Undirected(v[k], v[(k + 1) % 3]));
      const int inside = static_cast<int>(
          std::count_if(around.begin(), around.end(), [&](int o) { return patch_of[o] == id; }));
      if (inside == 1) next.emplace(v[k], v[(k + 1) % 3]);
    }
  }
  while (!next.empty()) {
    std::vector<int> loop = {next.begin()->first};
    auto it = next.begin();
    while (it != next.end()) {
      const int to = it->second;
      next.erase(it);
      if (to == loop.front()) break;
      loop.push_back(to);
      it = next.find(to);
    }
    if (loop.size() < 3) continue;
    const double area = LoopArea(loop, points, patch->normal);
    (area > 0.0 ? patch->outer : patch->holes).push_back(std::move(loop));
    patch->area += area;
  }
}

// Dihedral angle (degrees, 0..90: the fold either way) between two triangles' planes.
double FoldDeg(const Triangle& a, const Triangle& b) {
  return RadToDeg(std::acos(std::min(1.0, std::abs(a.normal.dot(b.normal)))));
}

// Counts tessellation and feature edges and marks the facets of curved surfaces.
void ClassifyEdges(const MeshTopology& topo, const std::vector<int>& patch_of,
                   const MeshToCaoOptions& options, std::vector<Patch>* patches,
                   std::vector<Edge>* features, MeshToCaoSummary* summary) {
  std::vector<int> smooth_sides(patches->size(), 0);
  for (const auto& [edge, around] : topo.faces_of_edge) {
    if (around.size() == 2 && patch_of[around[0]] == patch_of[around[1]]) {
      ++summary->tessellation_edges;
      continue;
    }
    if (around.size() == 2 && FoldDeg(topo.triangles[around[0]], topo.triangles[around[1]]) <=
                                  options.feature_angle_deg) {
      ++smooth_sides[patch_of[around[0]]];
      ++smooth_sides[patch_of[around[1]]];
      continue;
    }
    features->push_back(edge);
  }
  summary->feature_edges = static_cast<int>(features->size());
  for (size_t p = 0; p < patches->size(); ++p)
    (*patches)[p].curved = smooth_sides[p] >= 2;
}

// Marks as openings the open patches (no side shared with another patch) parallel to a larger
// face within options.opening_distance in front of it, and moves their outlines onto that face.
void FindOpenings(const MeshTopology& topo, const std::vector<int>& patch_of,
                  const MeshToCaoOptions& options, std::vector<Patch>* patches,
                  std::vector<Eigen::Vector3d>* points) {
  const double cos_parallel = std::cos(DegToRad(options.coplanar_angle_deg));
  for (size_t p = 0; p < patches->size(); ++p) {
    Patch& patch = (*patches)[p];
    if (patch.curved || patch.outer.size() != 1 || !patch.holes.empty()) continue;
    bool open = true;
    for (int t : patch.triangles) {
      for (int k = 0; k < 3 && open; ++k) {
        const std::array<int, 3>& v = topo.triangles[t].v;
        for (int o : topo.faces_of_edge.at(Undirected(v[k], v[(k + 1) % 3])))
          open = open && patch_of[o] == static_cast<int>(p);
      }
    }
    if (!open) continue;
    for (const Patch& wall : *patches) {
      if (&wall == &patch || wall.curved || wall.opening || wall.area <= patch.area ||
          std::abs(wall.normal.dot(patch.normal)) < cos_parallel) {
        continue;
      }
      const Eigen::Vector3d n = wall.normal.dot(patch.normal) > 0.0 ? wall.normal : -wall.normal;
      const double offset = wall.normal.dot(patch.normal) > 0.0 ? wall.offset : -wall.offset;
      const std::vector<int>& outline = patch.outer.front();
      const bool near = std::all_of(outline.begin(), outline.end(), [&](int i) {
        return std::abs(n.dot((*points)[i]) - offset) <= options.opening_distance;
      });
      if (!near) continue;
      patch.opening = true;
      for (int i : outline)
        (*points)[i] -= (n.dot((*points)[i]) - offset) * n;
      break;
    }
  }
}

// The 3D lines of `lines` joined where two meet end to end on one straight run (and no other
// line ends there), as chains of points.
std::vector<std::vector<int>> JoinCollinearLines(const std::vector<Edge>& lines,
                                                 const std::vector<Eigen::Vector3d>& points,
                                                 double tolerance, int* removed) {
  std::map<int, std::vector<int>> at;  // point -> lines ending there
  for (size_t i = 0; i < lines.size(); ++i) {
    at[lines[i].first].push_back(static_cast<int>(i));
    at[lines[i].second].push_back(static_cast<int>(i));
  }
  std::vector<char> used(lines.size(), 0);
  std::vector<std::vector<int>> chains;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (used[i]) continue;
    used[i] = 1;
    std::vector<int> chain = {lines[i].first, lines[i].second};
    for (int end = 0; end < 2; ++end) {
      while (true) {
        const int tip = chain.back(), before = chain[chain.size() - 2];
        const std::vector<int>& there = at[tip];
        if (there.size() != 2) break;
        const int other = used[there[0]] ? there[1] : there[0];
        if (used[other]) break;
        const int far = lines[other].first == tip ? lines[other].second : lines[other].first;
        if (DistanceToSegment3(points[tip], points[before], points[far]) > tolerance) break;
        used[other] = 1;
        chain.push_back(far);
      }
      std::reverse(chain.begin(), chain.end());
    }
    *removed += static_cast<int>(chain.size()) - 2;
    chains.push_back({chain.front(), chain.back()});
  }
  return chains;
}

// The points that `cao` uses, renumbered in order of first use.
void KeepUsedPoints(const std::vector<Eigen::Vector3d>& points, CaoModel* cao) {
  std::unordered_map<int, int> index;
  auto use = [&](int& i) {
    const auto [it, added] = index.emplace(i, static_cast<int>(cao->points.size()));
    if (added) cao->points.push_back(points[i]);
    i = it->second;
  };
  for (std::vector<int>& face : cao->faces) {
    for (int& i : face)
      use(i);
  }
  for (std::array<int, 2>& line : cao->lines) {
    use(line[0]);
    use(line[1]);
  }
}

// Throws InputError naming `source` unless every point is finite and within kMaxCoordinateM of
// the origin on each axis (so that the welding cubes' integer indices cannot overflow) and every
// index refers to a point.
void CheckMesh(const ImportMesh& mesh, const std::string& source) {
  for (const Eigen::Vector3d& p : mesh.points) {
    if (!(p.cwiseAbs().maxCoeff() <= kMaxCoordinateM)) {
      throw InputError(Located(source, 0, "a point is not finite or lies over 1e7 m out"));
    }
  }
  const auto valid = [&](int i) { return i >= 0 && static_cast<size_t>(i) < mesh.points.size(); };
  for (const std::array<int, 3>& t : mesh.triangles) {
    if (!std::all_of(t.begin(), t.end(), valid))
      throw InputError(Located(source, 0, "a triangle refers to a missing point"));
  }
  for (const std::array<int, 2>& l : mesh.lines) {
    if (!std::all_of(l.begin(), l.end(), valid))
      throw InputError(Located(source, 0, "a line refers to a missing point"));
  }
}

}  // namespace

bool MeshToCaoOptions::Check(std::string* why) const {
  if (!(feature_angle_deg > 0.0 && feature_angle_deg < 90.0)) {
    *why = "the feature angle must be in (0, 90) degrees";
    return false;
  }
  if (!(merge_tolerance >= 1e-9 && merge_tolerance <= 0.1)) {
    *why = "the merge tolerance must be in [1e-9, 0.1] metres";
    return false;
  }
  if (!(coplanar_angle_deg > 0.0 && coplanar_angle_deg < feature_angle_deg)) {
    *why = "the coplanar angle must be in (0, feature angle) degrees";
    return false;
  }
  if (!(opening_distance >= 0.0 && opening_distance <= 0.5)) {
    *why = "the opening distance must be in [0, 0.5] metres";
    return false;
  }
  return true;
}

std::vector<int> WeldPoints(const std::vector<Eigen::Vector3d>& points, double tolerance) {
  // Points hashed into cubes of side `tolerance`: a match lies in one of the 27 around.
  std::map<std::array<long long, 3>, std::vector<int>> cubes;
  auto cube = [&](const Eigen::Vector3d& p) {
    return std::array<long long, 3>{static_cast<long long>(std::floor(p.x() / tolerance)),
                                    static_cast<long long>(std::floor(p.y() / tolerance)),
                                    static_cast<long long>(std::floor(p.z() / tolerance))};
  };
  std::vector<int> map(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const std::array<long long, 3> c = cube(points[i]);
    int found = -1;
    for (long long dx = -1; dx <= 1 && found < 0; ++dx) {
      for (long long dy = -1; dy <= 1 && found < 0; ++dy) {
        for (long long dz = -1; dz <= 1 && found < 0; ++dz) {
          const auto it = cubes.find({c[0] + dx, c[1] + dy, c[2] + dz});
          if (it == cubes.end()) continue;
          for (int j : it->second) {
            if ((points[j] - points[i]).norm() <= tolerance) found = j;
          }
        }
      }
    }
    map[i] = found >= 0 ? found : static_cast<int>(i);
    if (found < 0) cubes[c].push_back(static_cast<int>(i));
  }
  return map;
}

std::vector<int> WithoutCollinear(const std::vector<int>& loop,
                                  const std::vector<Eigen::Vector3d>& points, double tolerance) {
  std::vector<int> kept = loop;
  bool changed = true;
  while (changed && kept.size() > 3) {
    changed = false;
    for (size_t i = 0; i < kept.size() && kept.size() > 3; ++i) {
      const Eigen::Vector3d& prev = points[kept[(i + kept.size() - 1) % kept.size()]];
      const Eigen::Vector3d& next = points[kept[(i + 1) % kept.size()]];
      if (DistanceToSegment3(points[kept[i]], prev, next) <= tolerance) {
        kept.erase(kept.begin() + static_cast<long>(i));
        changed = true;
      }
    }
  }
  return kept;
}

CaoModel MeshToCao(const ImportMesh& mesh, const MeshToCaoOptions& options,
                   const std::string& source, MeshToCaoSummary* summary) {
  std::string why;
  if (!options.Check(&why)) throw InputError(Located(source, 0, why));
  CheckMesh(mesh, source);
  MeshToCaoSummary unused;
  if (summary == nullptr) summary = &unused;
  *summary = MeshToCaoSummary();
  summary->input_points = static_cast<int>(mesh.points.size());
  summary->input_triangles = static_cast<int>(mesh.triangles.size());
  summary->input_lines = static_cast<int>(mesh.lines.size());
  std::vector<Eigen::Vector3d> points = mesh.points;
  const std::vector<int> weld = WeldPoints(points, options.merge_tolerance);
  for (size_t i = 0; i < weld.size(); ++i)
    summary->welded_points += weld[i] != static_cast<int>(i) ? 1 : 0;
  const MeshTopology topo = Topology(mesh, weld, options.merge_tolerance, summary);
  std::vector<int> patch_of;
  std::vector<Patch> patches = GrowPatches(topo, points, options, &patch_of);
  for (size_t p = 0; p < patches.size(); ++p)
    BoundaryLoops(topo, patch_of, static_cast<int>(p), points, &patches[p]);
  std::vector<Edge> features;
  ClassifyEdges(topo, patch_of, options, &patches, &features, summary);
  FindOpenings(topo, patch_of, options, &patches, &points);

  CaoModel cao;
  std::vector<Edge> lines;
  std::map<Edge, char> on_face;
  auto add_loop_lines = [&](const std::vector<int>& loop) {
    for (size_t i = 0; i < loop.size(); ++i)
      lines.push_back(Undirected(loop[i], loop[(i + 1) % loop.size()]));
  };
  for (const Patch& patch : patches) {
    summary->curved_facets += patch.curved ? 1 : 0;
    if (patch.curved) continue;
    for (const std::vector<int>& outer : patch.outer) {
      const std::vector<int> loop = WithoutCollinear(outer, points, options.merge_tolerance);
      summary->collinear_points += static_cast<int>(outer.size() - loop.size());
      if (patch.opening) {
        ++summary->openings;
        add_loop_lines(loop);
        continue;
      }
      cao.faces.push_back(loop);
      summary->merged_triangles +=
          patch.triangles.size() > 1 ? static_cast<int>(patch.triangles.size()) : 0;
      for (size_t i = 0; i < outer.size(); ++i)
        on_face[Undirected(outer[i], outer[(i + 1) % outer.size()])] = 1;
    }
    for (const std::vector<int>& hole : patch.holes) {
      ++summary->holes;
      add_loop_lines(WithoutCollinear(hole, points, options.merge_tolerance));
    }
  }
  for (const Edge& e : features) {
    if (!on_face.count(e) && patches[patch_of[topo.faces_of_edge.at(e).front()]].curved)
      lines.push_back(e);
  }
  for (const std::array<int, 2>& line : mesh.lines) {
    if (weld[line[0]] != weld[line[1]]) lines.push_back(Undirected(weld[line[0]], weld[line[1]]));
  }
  std::sort(lines.begin(), lines.end());
  lines.erase(std::unique(lines.begin(), lines.end()), lines.end());
  for (const std::vector<int>& chain :
       JoinCollinearLines(lines, points, options.merge_tolerance, &summary->collinear_points))
    cao.lines.push_back({chain[0], chain[1]});
  summary->faces = static_cast<int>(cao.faces.size());
  summary->lines = static_cast<int>(cao.lines.size());
  if (cao.faces.empty() && cao.lines.empty())
    throw InputError(Located(source, 0, "no face or line left after the import"));
  KeepUsedPoints(points, &cao);
  cao.line_names.assign(cao.lines.size(), "");
  cao.face_names.assign(cao.faces.size(), "");
  cao.files.push_back(source);
  return cao;
}

}  // namespace linetrack
