#include "models/render/frame_decals.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include "models/navigable_area.h"
#include "models/render/procedural.h"

namespace linetrack {
namespace {

constexpr double kOnPlaneTol = 1e-3;  // metres: a line lies on a face within this
constexpr double kFloorTol = 0.02;    // metres: a chain end stands on the face's bottom

double DistanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b) {
  const Eigen::Vector3d d = b - a;
  const double t = std::clamp((p - a).dot(d) / std::max(d.squaredNorm(), 1e-300), 0.0, 1.0);
  return (a + t * d - p).norm();
}

bool IsFaceEdge(const WireframeModel& model, const Segment3& s) {
  for (const ModelFace& face : model.faces()) {
    for (size_t k = 0; k < face.corners.size(); ++k) {
      const Eigen::Vector3d& a = face.corners[k];
      const Eigen::Vector3d& b = face.corners[(k + 1) % face.corners.size()];
      if (DistanceToSegment(s.a, a, b) < kOnPlaneTol && DistanceToSegment(s.b, a, b) < kOnPlaneTol)
        return true;
    }
  }
  return false;
}

int HostFace(const WireframeModel& model, const Segment3& s) {
  for (size_t f = 0; f < model.faces().size(); ++f) {
    const ModelFace& face = model.faces()[f];
    if (face.Degenerate()) continue;
    if (std::abs(face.normal.dot(s.a) - face.offset) > kOnPlaneTol ||
        std::abs(face.normal.dot(s.b) - face.offset) > kOnPlaneTol) {
      continue;
    }
    Eigen::Vector3d e1, e2;
    PlaneBasis(face.normal, &e1, &e2);
    if (InsidePlanarPolygon(face.corners, 0.5 * (s.a + s.b), e1, e2)) return static_cast<int>(f);
  }
  return -1;
}

int Find(std::vector<int>* parent, int i) {
  while ((*parent)[i] != i)
    i = (*parent)[i] = (*parent)[(*parent)[i]];
  return i;
}

// Orders the vertices of a group whose vertices all have degree <= 2 into a path or a cycle;
// returns false otherwise. *closed tells which.
bool OrderChain(const WireframeModel& model, const std::vector<int>& edge_ids,
                std::vector<int>* order, bool* closed) {
  std::map<int, std::vector<int>> neighbours;
  for (int id : edge_ids) {
    const ModelEdge& e = model.edges()[id];
    neighbours[e.v0].push_back(e.v1);
    neighbours[e.v1].push_back(e.v0);
  }
  int start = neighbours.begin()->first, ends = 0;
  for (const auto& [v, n] : neighbours) {
    if (n.size() > 2) return false;
    if (n.size() == 1) {
      if (ends == 0) start = v;
      ++ends;
    }
  }
  if (ends != 0 && ends != 2) return false;
  order->assign(1, start);
  int previous = -1, current = start;
  while (true) {
    int next = -1;
    for (int n : neighbours[current]) {
      if (n != previous) next = n;
    }
    if (next < 0 || next == start) break;
    order->push_back(next);
    previous = current;
    current = next;
  }
  *closed = ends == 0;
  return order->size() == neighbours.size();
}

}  // namespace

void PlaneBasis(const Eigen::Vector3d& n, Eigen::Vector3d* e1, Eigen::Vector3d* e2) {
  Eigen::Vector3d h = n.cross(Eigen::Vector3d::UnitZ());
  if (h.norm() < 1e-6) h = Eigen::Vector3d::UnitX();
  *e1 = h.normalized();
  *e2 = n.cross(*e1).normalized();
}

bool InsidePlanarPolygon(const std::vector<Eigen::Vector3d>& polygon, const Eigen::Vector3d& p,
                         const Eigen::Vector3d& e1, const Eigen::Vector3d& e2) {
  Polygon2 flat;
  for (const Eigen::Vector3d& c : polygon)
    flat.vertices.emplace_back(e1.dot(c), e2.dot(c));
  return flat.Contains({e1.dot(p), e2.dot(p)});
}

std::vector<FrameGroup> FindFrameGroups(const WireframeModel& model, int* undrawn) {
  std::vector<int> lines, hosts;
  int skipped = 0;
  for (const ModelEdge& e : model.edges()) {
    if (!e.from_line || IsFaceEdge(model, e.segment)) continue;
    const int host = HostFace(model, e.segment);
    if (host < 0) {
      ++skipped;
      continue;
    }
    lines.push_back(e.id);
    hosts.push_back(host);
  }
  if (undrawn) *undrawn = skipped;

  // Union-find over lines sharing a vertex on the same host face.
  std::vector<int> parent(lines.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (size_t i = 0; i < lines.size(); ++i) {
    for (size_t j = i + 1; j < lines.size(); ++j) {
      const ModelEdge& a = model.edges()[lines[i]];
      const ModelEdge& b = model.edges()[lines[j]];
      const bool touch = a.v0 == b.v0 || a.v0 == b.v1 || a.v1 == b.v0 || a.v1 == b.v1;
      if (touch && hosts[i] == hosts[j]) parent[Find(&parent, i)] = Find(&parent, j);
    }
  }
  std::map<int, FrameGroup> by_root;
  for (size_t i = 0; i < lines.size(); ++i) {
    FrameGroup& g = by_root[Find(&parent, i)];
    g.host_face = hosts[i];
    g.edge_ids.push_back(lines[i]);
  }

  std::vector<FrameGroup> groups;
  for (auto& [root, g] : by_root) {
    std::vector<int> order;
    bool closed = false;
    if (OrderChain(model, g.edge_ids, &order, &closed)) {
      const double bottom = [&] {
        double z = std::numeric_limits<double>::infinity();
        for (const Eigen::Vector3d& c : model.faces()[g.host_face].corners)
          z = std::min(z, c.z());
        return z;
      }();
      const Eigen::Vector3d& first = model.vertices()[order.front()];
      const Eigen::Vector3d& last = model.vertices()[order.back()];
      g.door = !closed && order.size() >= 3 && std::abs(first.z() - bottom) < kFloorTol &&
               std::abs(last.z() - bottom) < kFloorTol;
      if (closed || g.door) {
        for (int v : order)
          g.opening.push_back(model.vertices()[v]);
      }
    }
    groups.push_back(std::move(g));
  }
  return groups;
}

std::vector<RenderSurface> FrameDecals(const WireframeModel& model, const FrameGroup& group,
                                       double host_albedo, double width, uint64_t seed) {
  const ModelFace& host = model.faces()[group.host_face];
  SeededDraws draws(HashCombine(seed, group.edge_ids.front()));
  const double jitter = draws.Uniform(-0.03, 0.03);
  const bool bright_host = host_albedo >= 0.5;
  const double trim = bright_host ? 0.28 + jitter : std::min(0.92, host_albedo + 0.38 + jitter);
  const double leaf = bright_host ? 0.52 + jitter : 0.2 + jitter;
  const double pane = bright_host ? 0.93 : 0.1;

  RenderSurface base;
  base.normal = host.normal;
  base.offset = host.offset;
  base.decal = true;
  base.model_face = group.host_face;

  std::vector<RenderSurface> out;
  Eigen::Vector3d e1, e2;
  PlaneBasis(host.normal, &e1, &e2);
  if (!group.opening.empty()) {
    RenderSurface fill = base;
    fill.kind = group.door ? SurfaceKind::kDoorLeaf : SurfaceKind::kWindowPane;
    fill.albedo = group.door ? leaf : pane;
    fill.polygon = group.opening;
    out.push_back(fill);
  }
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  std::map<int, int> degree;
  for (int id : group.edge_ids) {
    const ModelEdge& e = model.edges()[id];
    centroid += 0.5 * (e.segment.a + e.segment.b) / group.edge_ids.size();
    ++degree[e.v0];
    ++degree[e.v1];
  }
  for (int id : group.edge_ids) {
    const ModelEdge& e = model.edges()[id];
    const Eigen::Vector3d dir = e.segment.Direction();
    const Eigen::Vector3d across = host.normal.cross(dir).normalized();
    const Eigen::Vector3d mid = 0.5 * (e.segment.a + e.segment.b);
    double side = 0.0;  // +1: band on the +across side; 0: centred on the line
    if (!group.opening.empty()) {
      side = InsidePlanarPolygon(group.opening, mid + 1e-3 * across, e1, e2) ? -1.0 : 1.0;
    } else if (std::abs(across.dot(centroid - mid)) > 1e-6) {
      side = across.dot(centroid - mid) > 0.0 ? -1.0 : 1.0;
    }
    // Bands reach past ends shared with another line of the group so that corners close.
    const Eigen::Vector3d a = e.segment.a - (degree[e.v0] > 1 ? width : 0.0) * dir;
    const Eigen::Vector3d b = e.segment.b + (degree[e.v1] > 1 ? width : 0.0) * dir;
    const Eigen::Vector3d lo = (side == 0.0 ? -0.5 * width : 0.0) * across;
    const Eigen::Vector3d hi = (side == 0.0 ? 0.5 * width : side * width) * across;
    RenderSurface band = base;
    band.kind = SurfaceKind::kFrameTrim;
    band.albedo = trim;
    band.polygon = {a + lo, b + lo, b + hi, a + hi};
    out.push_back(band);
  }
  return out;
}

}  // namespace linetrack
