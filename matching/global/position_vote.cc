#include "matching/global/position_vote.h"

#include <algorithm>
#include <cmath>

#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack {

namespace {

// Shrinks [lo, hi] to the D >= 0 with c + s D >= 0.
void KeepNonNegative(double c, double s, double* lo, double* hi) {
  if (std::abs(s) < 1e-12) {
    if (c < 0.0) *hi = -1.0;
    return;
  }
  const double root = -c / s;
  if (s > 0.0) {
    *lo = std::max(*lo, root);
  } else {
    *hi = std::min(*hi, root);
  }
}

// tan(elevation) of a level-frame ray (level y points down); false when the ray is vertical.
bool TanElevation(const Eigen::Vector3d& ray, double* t) {
  const double horizontal = std::hypot(ray.x(), ray.z());
  if (horizontal < 1e-9) return false;
  *t = -ray.y() / horizontal;
  return true;
}

}  // namespace

bool PositionVoteOptions::Check(std::string* why) const {
  if (!(cell_m > 0.0) || !(heading_step_deg > 0.0) || peaks_per_search < 1 ||
      !(peak_separation_m >= 0.0) || !(min_line_length_px >= 0.0) || !(gate_sigmas > 0.0)) {
    *why =
        "position vote: cell_m, heading_step_deg, gate_sigmas > 0, peaks_per_search >= 1, "
        "peak_separation_m and min_line_length_px >= 0";
    return false;
  }
  if (!(tolerance.extent_slack_px >= 0.0) || !(tolerance.focal_px > 0.0) ||
      !(tolerance.max_range_m > 0.0)) {
    *why = "position vote: extent_slack_px >= 0, focal_px and max_range_m > 0";
    return false;
  }
  return true;
}

std::optional<PositionLocus> VerticalEdgeLocus(const ObservedLine& line, const MatchEdge& edge,
                                               double height, double heading,
                                               const LocusTolerance& tolerance) {
  const double z_lo = std::min(edge.a.z(), edge.b.z()) - height;
  const double z_hi = std::max(edge.a.z(), edge.b.z()) - height;
  double lo = 0.05, hi = tolerance.max_range_m;
  for (const Eigen::Vector3d& ray : {line.ray_a, line.ray_b}) {
    double t = 0.0;
    if (!TanElevation(ray, &t)) continue;
    const double tau = tolerance.extent_slack_px / tolerance.focal_px * (1.0 + t * t);
    KeepNonNegative(-z_lo, t + tau, &lo, &hi);    // z_lo <= D (t + tau)
    KeepNonNegative(z_hi, -(t - tau), &lo, &hi);  // D (t - tau) <= z_hi
  }
  if (lo > hi) return std::nullopt;
  const double bearing = heading - line.bearing;  // world direction camera -> edge
  const Eigen::Vector2d toward(std::cos(bearing), std::sin(bearing));
  return PositionLocus{edge.foot - lo * toward, edge.foot - hi * toward};
}

std::optional<PositionLocus> HorizontalEdgeLocus(const ObservedLine& line, const MatchEdge& edge,
                                                 double height, double heading,
                                                 const LocusTolerance& tolerance) {
  const Eigen::Vector2d v = edge.dir.head<2>().normalized();
  const Eigen::Vector2d n(-v.y(), v.x());
  const Eigen::Vector2d a = edge.a.head<2>();
  const double length = (edge.b - edge.a).head<2>().norm();
  const double dz = edge.a.z() - height;
  const Eigen::Matrix3d world_from_level = LevelFromWorld(heading).transpose();
  double offset = 0.0, along_lo = -1e300, along_hi = 1e300;
  for (const Eigen::Vector3d& ray : {line.ray_a, line.ray_b}) {
    const Eigen::Vector3d d = world_from_level * ray;
    if (std::abs(d.z()) < 1e-9) return std::nullopt;  // a ray at the edge's height: no range
    const double lambda = dz / d.z();
    const Eigen::Vector2d o = lambda * d.head<2>();
    if (!(lambda > 0.0) || o.norm() > tolerance.max_range_m) return std::nullopt;
    const double slack = tolerance.extent_slack_px / tolerance.focal_px * lambda;
    offset -= 0.5 * o.dot(n);
    along_lo = std::max(along_lo, -o.dot(v) - slack);
    along_hi = std::min(along_hi, length - o.dot(v) + slack);
  }
  if (along_lo > along_hi) return std::nullopt;
  return PositionLocus{a + along_lo * v + offset * n, a + along_hi * v + offset * n};
}

PositionVote::PositionVote(const WireframeModel& model, const NavigableArea& area,
                           const PositionVoteOptions& options)
    : options_(options) {
  std::string why;
  if (!options_.Check(&why)) throw InputError(why);
  std::vector<int> ids(model.edges().size());
  for (size_t i = 0; i < ids.size(); ++i)
    ids[i] = static_cast<int>(i);
  for (const MatchEdge& e : PrepareEdges(model, ids)) {
    if (e.vertical) {
      verticals_.push_back(e);
      continue;
    }
    if (std::abs(e.dir.z()) > 1e-6 || (e.b - e.a).norm() < 1e-9) continue;  // slanted: no vote
    auto same = [&](const EdgeGroup& g) { return std::abs(g.dir.dot(e.dir)) > 1.0 - 1e-6; };
    auto it = std::find_if(groups_.begin(), groups_.end(), same);
    if (it == groups_.end()) it = groups_.insert(groups_.end(), EdgeGroup{e.dir, {}});
    it->edges.push_back(e);
  }
  origin_ = area.BoundsMin();
  const Eigen::Vector2d span = area.BoundsMax() - origin_;
  nx_ = std::max(1, static_cast<int>(std::ceil(span.x() / options_.cell_m)));
  ny_ = std::max(1, static_cast<int>(std::ceil(span.y() / options_.cell_m)));
  inside_.resize(static_cast<size_t>(nx_) * ny_);
  // A cell counts when its centre or a corner is in the area: a position near the clearance
  // border may lie in a cell whose centre is not.
  const double h = 0.5 * options_.cell_m;
  for (int i = 0; i < nx_ * ny_; ++i) {
    const Eigen::Vector2d c = CellCentre(i);
    inside_[i] = 0;
    for (const Eigen::Vector2d& p :
         {c, Eigen::Vector2d(c.x() - h, c.y() - h), Eigen::Vector2d(c.x() + h, c.y() - h),
          Eigen::Vector2d(c.x() - h, c.y() + h), Eigen::Vector2d(c.x() + h, c.y() + h)}) {
      if (area.Contains(p)) inside_[i] = 1;
    }
    inside_count_ += inside_[i];
  }
  inside_count_ = std::max(inside_count_, 1);
}

Eigen::Vector2d PositionVote::CellCentre(int index) const {
  return origin_ + options_.cell_m * Eigen::Vector2d(index % nx_ + 0.5, index / nx_ + 0.5);
}

void PositionVote::Mark(const PositionLocus& locus, int stamp, std::vector<int>* cells,
                        std::vector<int>* stamps) const {
  const double cell = options_.cell_m;
  const Eigen::Vector2d from = (locus.from - origin_) / cell, to = (locus.to - origin_) / cell;
  // Clip the segment to the grid (Liang-Barsky on [-1, n + 1]: neighbours of edge cells count).
  double t0 = 0.0, t1 = 1.0;
  const Eigen::Vector2d d = to - from;
  const double lo[2] = {-1.0, -1.0}, hi[2] = {nx_ + 1.0, ny_ + 1.0};
  for (int k = 0; k < 2; ++k) {
    if (std::abs(d[k]) < 1e-12) {
      if (from[k] < lo[k] || from[k] > hi[k]) return;
      continue;
    }
    double a = (lo[k] - from[k]) / d[k], b = (hi[k] - from[k]) / d[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  if (t0 > t1) return;
  const int steps = 1 + static_cast<int>(std::ceil(2.0 * (t1 - t0) * d.norm()));
  int last_x = -2, last_y = -2;  // the previous sample's cell (outside the clipped grid)
  for (int s = 0; s <= steps; ++s) {
    const Eigen::Vector2d p = from + (t0 + (t1 - t0) * s / steps) * d;
    const int cx = static_cast<int>(std::floor(p.x())), cy = static_cast<int>(std::floor(p.y()));
    if (cx == last_x && cy == last_y) continue;  // the same 3 x 3 neighbourhood, already marked
    last_x = cx;
    last_y = cy;
    for (int y = std::max(0, cy - 1); y <= std::min(ny_ - 1, cy + 1); ++y) {
      for (int x = std::max(0, cx - 1); x <= std::min(nx_ - 1, cx + 1); ++x) {
        const int i = y * nx_ + x;
        if ((*stamps)[i] == stamp) continue;
        (*stamps)[i] = stamp;
        cells->push_back(i);
      }
    }
  }
}

std::vector<std::vector<int>> PositionVote::FittingGroups(const std::vector<ObservedLine>& lines,
                                                          const HeadingInterval& headings) const {
  std::vector<std::vector<int>> fitting(lines.size());
  HeadingInterval parts[kMaxDirectionIntervals];
  for (size_t l = 0; l < lines.size(); ++l) {
    for (size_t g = 0; g < groups_.size(); ++g) {
      if (DirectionIntervals(lines[l], groups_[g].dir, headings, options_.gate_sigmas, parts) > 0)
        fitting[l].push_back(static_cast<int>(g));
    }
  }
  return fitting;
}

void PositionVote::Vote(const std::vector<ObservedLine>& lines,
                        const std::vector<std::vector<int>>& groups, double height, double heading,
                        std::vector<float>* votes, std::vector<int>* stamps) const {
  votes->assign(inside_.size(), 0.0f);
  stamps->assign(inside_.size(), -1);
  std::vector<int> cells;
  for (size_t l = 0; l < lines.size(); ++l) {
    const ObservedLine& line = lines[l];
    if (line.length_px < options_.min_line_length_px) continue;
    const int stamp = static_cast<int>(l);
    cells.clear();
    if (line.maybe_vertical) {
      for (const MatchEdge& e : verticals_) {
        const auto locus = VerticalEdgeLocus(line, e, height, heading, options_.tolerance);
        if (locus) Mark(*locus, stamp, &cells, stamps);
      }
    }
    for (int g : groups[l]) {
      for (const MatchEdge& e : groups_[g].edges) {
        const auto locus = HorizontalEdgeLocus(line, e, height, heading, options_.tolerance);
        if (locus) Mark(*locus, stamp, &cells, stamps);
      }
    }
    if (cells.empty()) continue;
    // The line's weight, ln(1 / share) of the area its loci mark: a line that fits everywhere
    // says little about where the camera is (the information of "this line is an edge's image").
    const double share = static_cast<double>(cells.size()) / static_cast<double>(inside_count_);
    const float weight = static_cast<float>(std::max(0.0, -std::log(std::min(1.0, share))));
    for (int i : cells)
      (*votes)[i] += weight;
  }
}

std::vector<float> PositionVote::Votes(const std::vector<ObservedLine>& lines, double height,
                                       double heading) const {
  const double half = 0.5 * DegToRad(options_.heading_step_deg);
  std::vector<float> votes;
  std::vector<int> stamps;
  Vote(lines, FittingGroups(lines, {heading - half, heading + half}), height, heading, &votes,
       &stamps);
  return votes;
}

std::vector<PositionPeak> PositionVote::Peaks(const std::vector<ObservedLine>& lines, double height,
                                              double heading, double bound) const {
  const double step = DegToRad(options_.heading_step_deg);
  const int half_steps = static_cast<int>(std::floor(bound / step + 1e-9));
  std::vector<PositionPeak> all;
  std::vector<float> votes;
  std::vector<int> stamps;
  for (int k = -half_steps; k <= half_steps; ++k) {
    const double h = heading + k * step;
    Vote(lines, FittingGroups(lines, {h - 0.5 * step, h + 0.5 * step}), height, h, &votes, &stamps);
    for (int y = 0; y < ny_; ++y) {
      for (int x = 0; x < nx_; ++x) {
        const int i = y * nx_ + x;
        if (!inside_[i] || votes[i] <= 0.0f) continue;
        bool is_max = true;  // a local maximum of its 3 x 3 neighbourhood (ties: first cell)
        for (int yy = std::max(0, y - 1); is_max && yy <= std::min(ny_ - 1, y + 1); ++yy) {
          for (int xx = std::max(0, x - 1); xx <= std::min(nx_ - 1, x + 1); ++xx) {
            const int j = yy * nx_ + xx;
            if (votes[j] > votes[i] || (votes[j] == votes[i] && j < i)) is_max = false;
          }
        }
        if (is_max) all.push_back({CellCentre(i), h, votes[i]});
      }
    }
  }
  std::stable_sort(all.begin(), all.end(),
                   [](const PositionPeak& a, const PositionPeak& b) { return a.votes > b.votes; });
  std::vector<PositionPeak> kept;
  for (const PositionPeak& p : all) {
    if (static_cast<int>(kept.size()) >= options_.peaks_per_search) break;
    const bool near = std::any_of(kept.begin(), kept.end(), [&](const PositionPeak& q) {
      return (q.position - p.position).norm() < options_.peak_separation_m;
    });
    if (!near) kept.push_back(p);
  }
  return kept;
}

}  // namespace linetrack
