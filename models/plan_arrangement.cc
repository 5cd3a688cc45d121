#include "models/plan_arrangement.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <unordered_map>
#include <utility>

namespace linetrack {
namespace {

// Merges points closer than `radius` into one vertex (hash grid, neighbour cells searched).
class PointSnapper {
 public:
  PointSnapper(double radius, std::vector<Eigen::Vector2d>* points)
      : radius_(radius), cell_(std::max(radius, 1e-12) * 2.0), points_(points) {}

  int Add(const Eigen::Vector2d& p) {
    const long long cx = static_cast<long long>(std::floor(p.x() / cell_));
    const long long cy = static_cast<long long>(std::floor(p.y() / cell_));
    for (long long dx = -1; dx <= 1; ++dx) {
      for (long long dy = -1; dy <= 1; ++dy) {
        const auto it = grid_.find(Key(cx + dx, cy + dy));
        if (it == grid_.end()) continue;
        for (int id : it->second) {
          if (((*points_)[id] - p).norm() <= radius_) return id;
        }
      }
    }
    const int id = static_cast<int>(points_->size());
    points_->push_back(p);
    grid_[Key(cx, cy)].push_back(id);
    return id;
  }

 private:
  // Spatial hash of a cell (Teschner et al. 2003); unsigned so that far cells wrap, not overflow.
  static unsigned long long Key(long long x, long long y) {
    return static_cast<unsigned long long>(x) * 73856093ULL ^
           static_cast<unsigned long long>(y) * 19349663ULL;
  }
  double radius_;
  double cell_;
  std::vector<Eigen::Vector2d>* points_;
  std::unordered_map<unsigned long long, std::vector<int>> grid_;
};

int Find(std::vector<int>& parent, int x) {
  while (parent[x] != x)
    x = parent[x] = parent[parent[x]];
  return x;
}

// The walls in a uniform grid of their bounding boxes: the candidates that can meet a wall.
class WallGrid {
 public:
  WallGrid(const std::vector<PlanWall>& walls, double tolerance) : tolerance_(tolerance) {
    if (walls.empty()) return;
    Eigen::Vector2d lo = walls.front().segment.a, hi = lo;
    double total = 0.0;
    for (const PlanWall& w : walls) {
      lo = lo.cwiseMin(w.segment.a).cwiseMin(w.segment.b);
      hi = hi.cwiseMax(w.segment.a).cwiseMax(w.segment.b);
      total += w.segment.Length();
    }
    origin_ = lo;
    // About as many cells as walls, no smaller than the mean wall.
    const Eigen::Vector2d extent = (hi - lo).cwiseMax(Eigen::Vector2d::Constant(1e-9));
    cell_ =
        std::max({total / walls.size(), std::sqrt(extent.x() * extent.y() / walls.size()), 1e-6});
    cols_ = static_cast<int>(extent.x() / cell_) + 1;
    rows_ = static_cast<int>(extent.y() / cell_) + 1;
    cells_.assign(static_cast<size_t>(cols_) * rows_, {});
    for (size_t i = 0; i < walls.size(); ++i) {
      ForCells(walls[i].segment, [&](size_t c) { cells_[c].push_back(static_cast<int>(i)); });
    }
  }

  // Walls whose cells meet those of `s` (sorted, each once).
  std::vector<int> Near(const Segment2& s) const {
    std::vector<int> out;
    ForCells(s, [&](size_t c) { out.insert(out.end(), cells_[c].begin(), cells_[c].end()); });
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

 private:
  template <typename Visit>
  void ForCells(const Segment2& s, const Visit& visit) const {
    const Eigen::Vector2d lo = s.a.cwiseMin(s.b).array() - tolerance_;
    const Eigen::Vector2d hi = s.a.cwiseMax(s.b).array() + tolerance_;
    auto col = [&](double x) {
      return std::clamp(static_cast<int>(std::floor((x - origin_.x()) / cell_)), 0, cols_ - 1);
    };
    auto row = [&](double y) {
      return std::clamp(static_cast<int>(std::floor((y - origin_.y()) / cell_)), 0, rows_ - 1);
    };
    for (int r = row(lo.y()); r <= row(hi.y()); ++r) {
      for (int c = col(lo.x()); c <= col(hi.x()); ++c)
        visit(static_cast<size_t>(r) * cols_ + c);
    }
  }

  double tolerance_;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  double cell_ = 1.0;
  int cols_ = 0, rows_ = 0;
  std::vector<std::vector<int>> cells_;
};

// Parameters (0..1 along wall i) where the walls `near` cross, touch or overlap it.
std::vector<double> SplitParameters(const std::vector<PlanWall>& walls, size_t i,
                                    const std::vector<int>& near, double tolerance) {
  const Eigen::Vector2d a = walls[i].segment.a, d = walls[i].segment.b - a;
  const double len = d.norm();
  std::vector<double> params = {0.0, 1.0};
  for (int near_j : near) {
    const size_t j = static_cast<size_t>(near_j);
    const Eigen::Vector2d aj = walls[j].segment.a, dj = walls[j].segment.b - aj;
    const double lenj = dj.norm();
    if (j == i || lenj <= tolerance) continue;
    const double denom = Cross2(d, dj);
    if (std::abs(denom) > 1e-12 * len * lenj) {
      const double t = Cross2(aj - a, dj) / denom;
      const double u = Cross2(aj - a, d) / denom;
      if (t >= -tolerance / len && t <= 1.0 + tolerance / len && u >= -tolerance / lenj &&
          u <= 1.0 + tolerance / lenj) {
        params.push_back(std::clamp(t, 0.0, 1.0));
      }
    } else if (std::abs(Cross2(d, aj - a)) / len <= tolerance) {  // collinear
      for (const Eigen::Vector2d& p : {aj, Eigen::Vector2d(aj + dj)}) {
        const double t = (p - a).dot(d) / (len * len);
        if (t > 0.0 && t < 1.0) params.push_back(t);
      }
    }
  }
  std::sort(params.begin(), params.end());
  return params;
}

}  // namespace

PlanArrangement PlanArrangement::Build(const std::vector<PlanWall>& walls, double tolerance) {
  PlanArrangement arr;
  arr.tolerance_ = tolerance;
  PointSnapper snapper(2.0 * tolerance, &arr.vertices_);
  std::map<std::pair<int, int>, int> edge_of;
  const WallGrid grid(walls, tolerance);
  for (size_t i = 0; i < walls.size(); ++i) {
    const Segment2& s = walls[i].segment;
    if (s.Length() <= tolerance) continue;
    int previous = -1;
    for (double t : SplitParameters(walls, i, grid.Near(s), tolerance)) {
      const Eigen::Vector2d p = t == 0.0   ? s.a
                                : t == 1.0 ? s.b
                                           : Eigen::Vector2d(s.a + t * (s.b - s.a));
      const int id = snapper.Add(p);
      if (previous >= 0 && id != previous) {
        const std::pair<int, int> key = std::minmax(previous, id);
        auto [it, fresh] = edge_of.emplace(key, static_cast<int>(arr.edges_.size()));
        if (fresh) {
          arr.edges_.push_back({key.first, key.second});
          arr.faced_.push_back({false, false});
        }
        if (!walls[i].normal.isZero()) {
          const Eigen::Vector2d along = arr.vertices_[key.second] - arr.vertices_[key.first];
          arr.faced_[it->second][Cross2(along, walls[i].normal) > 0.0 ? 0 : 1] = true;
        }
      }
      previous = id;
    }
  }

  // Half-edge h runs along edge h / 2, from first to second when h is even.
  const int num_half = 2 * static_cast<int>(arr.edges_.size());
  auto origin = [&](int h) { return arr.edges_[h / 2][h % 2]; };
  auto dest = [&](int h) { return arr.edges_[h / 2][1 - h % 2]; };
  std::vector<std::vector<int>> out(arr.vertices_.size());
  for (int h = 0; h < num_half; ++h)
    out[origin(h)].push_back(h);
  std::vector<int> position(num_half);
  arr.neighbours_.resize(arr.vertices_.size());
  for (size_t v = 0; v < out.size(); ++v) {
    auto angle = [&](int h) {
      const Eigen::Vector2d d = arr.vertices_[dest(h)] - arr.vertices_[v];
      return std::atan2(d.y(), d.x());
    };
    std::sort(out[v].begin(), out[v].end(), [&](int a, int b) { return angle(a) < angle(b); });
    for (size_t k = 0; k < out[v].size(); ++k) {
      position[out[v][k]] = static_cast<int>(k);
      arr.neighbours_[v].push_back(dest(out[v][k]));
    }
  }

  std::vector<int> parent(arr.vertices_.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& e : arr.edges_)
    parent[Find(parent, e[0])] = Find(parent, e[1]);
  std::map<int, int> component_id;
  for (size_t v = 0; v < parent.size(); ++v) {
    if (!out[v].empty())
      component_id.emplace(Find(parent, static_cast<int>(v)), component_id.size());
  }
  arr.num_components_ = static_cast<int>(component_id.size());

  // Walk each cycle keeping the face on the left: at the head of h, take the outgoing half-edge
  // next clockwise from h's twin.
  std::vector<bool> visited(num_half, false);
  for (int start = 0; start < num_half; ++start) {
    if (visited[start]) continue;
    PlanCycle cycle;
    cycle.component = component_id[Find(parent, origin(start))];
    double twice_area = 0.0;
    for (int h = start; !visited[h];) {
      visited[h] = true;
      const Eigen::Vector2d& a = arr.vertices_[origin(h)];
      const Eigen::Vector2d& b = arr.vertices_[dest(h)];
      cycle.vertices.push_back(origin(h));
      twice_area += Cross2(a, b);
      cycle.length += (b - a).norm();
      if (arr.faced_[h / 2][h % 2]) cycle.facing_length += (b - a).norm();
      const std::vector<int>& around = out[dest(h)];
      const int k = position[h ^ 1];
      h = around[(k + around.size() - 1) % around.size()];
    }
    cycle.signed_area = 0.5 * twice_area;
    arr.cycles_.push_back(std::move(cycle));
  }
  return arr;
}

Ring2 PlanArrangement::CycleRing(const PlanCycle& cycle) const {
  Ring2 ring;
  for (int v : cycle.vertices)
    ring.push_back(vertices_[v]);
  return SimplifyRing(ring, tolerance_);
}

}  // namespace linetrack
