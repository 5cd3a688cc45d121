#include "matching/interpretation_tree.h"

#include <algorithm>
#include <numeric>
#include <optional>
#include <set>

namespace linetrack {
namespace {

// One level of the tree: a model edge and the lines that pass its unary constraint, with the
// heading interval each allows.
struct Level {
  int edge = -1;
  std::vector<int> lines;
  std::vector<HeadingInterval> headings;
};

class TreeSearch {
 public:
  TreeSearch(const std::vector<MatchEdge>& edges, const std::vector<ObservedLine>& lines,
             const PriorRegion& prior, const InterpretationTreeOptions& options,
             const std::vector<double>& line_caps, const LeafVisitor& visit,
             InterpretationTreeStats* stats, const std::vector<VerifiedBasin>* basins)
      : edges_(edges),
        lines_(lines),
        prior_(prior),
        options_(options),
        visit_(visit),
        stats_(stats),
        basins_(basins) {
    gate_.sigmas = options.gate_sigmas;
    gate_.extent_slack_px = options.extent_slack_px;
    gate_.focal_px = prior.focal_px;
    caps_ = line_caps.empty() ? std::vector<double>(lines.size(), 1.0) : line_caps;
  }

  void Run() {
    BuildLevels();
    const double min_width = DegToRad(options_.heading_bin_deg);
    FeasibleRegion root =
        FeasibleRegion::FromPrior(prior_.heading, prior_.centre, prior_.radius,
                                  std::max(min_width, prior_.heading.Width() / options_.max_bins));
    if (prior_.has_bounds) {
      for (HeadingBin& bin : root.bins) {
        bin.positions.ClipHalfPlane({1.0, 0.0}, -prior_.bounds_min.x());
        bin.positions.ClipHalfPlane({-1.0, 0.0}, prior_.bounds_max.x());
        bin.positions.ClipHalfPlane({0.0, 1.0}, -prior_.bounds_min.y());
        bin.positions.ClipHalfPlane({0.0, -1.0}, prior_.bounds_max.y());
      }
      if (root.bins.front().positions.Empty()) return;
    }
    used_.assign(lines_.size(), false);
    line_mark_.assign(lines_.size(), false);
    level_assigned_.assign(levels_.size(), -1);
    level_skipped_.assign(levels_.size(), false);
    regions_.resize(levels_.size() + 2);
    alive_.assign(levels_.size() + 2, std::vector<char>(candidate_line_.size(), 1));
    processed_.assign(levels_.size(), false);
    // Iterative deepening on the bound: from what all lines with a candidate could give, down
    // by deepening_lines mean caps per pass, until the visitor's own bound is reached.
    double top = 0.0;
    int with_candidates = 0;
    for (int line : candidate_line_) {
      if (line_mark_[line]) continue;
      line_mark_[line] = true;
      top += caps_[line];
      ++with_candidates;
    }
    std::fill(line_mark_.begin(), line_mark_.end(), false);
    const double step =
        options_.deepening_lines * (with_candidates > 0 ? top / with_candidates : 1.0);
    for (double pass = top - step;; pass -= step) {
      pass_bound_ = std::max(pass, 0.0);
      ++stats_->passes;
      Search(0, root);
      if (stats_->budget_exhausted || pass_bound_ <= visitor_bound_ || pass_bound_ <= 0.0) break;
    }
  }

 private:
  // Unary constraints: non-vertical edges against all lines, vertical edges against the lines
  // that can be images of vertical edges. Non-vertical levels first (they narrow the heading, so
  // the vertical wedges then cut few bins), each group by candidate count, fewest first; within a
  // level the longest lines first (model lines tend to be long).
  void BuildLevels() {
    for (size_t e = 0; e < edges_.size(); ++e) {
      Level level;
      level.edge = static_cast<int>(e);
      for (size_t j = 0; j < lines_.size(); ++j) {
        if (edges_[e].vertical) {
          if (!lines_[j].maybe_vertical) continue;
          const std::optional<HeadingInterval> h =
              UnaryVertical(lines_[j], edges_[e], prior_.height, prior_.heading, prior_.centre,
                            prior_.radius, gate_);
          if (!h) continue;
          level.lines.push_back(static_cast<int>(j));
          level.headings.push_back(*h);
        } else {
          const std::vector<HeadingInterval> h =
              UnaryNonVertical(lines_[j], edges_[e], prior_.height, prior_.heading, prior_.centre,
                               prior_.radius, gate_);
          if (h.empty()) continue;
          level.lines.push_back(static_cast<int>(j));
          level.headings.push_back({h.front().lo, h.back().hi});
        }
      }
      stats_->unary_candidates += static_cast<int>(level.lines.size());
      if (level.lines.empty()) continue;
      std::vector<size_t> order(level.lines.size());
      std::iota(order.begin(), order.end(), 0);
      std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        return lines_[level.lines[a]].length_px > lines_[level.lines[b]].length_px;
      });
      Level sorted;
      sorted.edge = level.edge;
      for (size_t i : order) {
        sorted.lines.push_back(level.lines[i]);
        sorted.headings.push_back(level.headings[i]);
      }
      levels_.push_back(std::move(sorted));
    }
    std::stable_sort(levels_.begin(), levels_.end(), [&](const Level& a, const Level& b) {
      if (edges_[a.edge].vertical != edges_[b.edge].vertical) return !edges_[a.edge].vertical;
      return a.lines.size() < b.lines.size();
    });
    // Candidates flattened: level d holds [offsets_[d], offsets_[d + 1]).
    offsets_.assign(1, 0);
    for (const Level& level : levels_) {
      for (int line : level.lines) {
        candidate_level_.push_back(static_cast<int>(offsets_.size()) - 1);
        candidate_line_.push_back(line);
      }
      offsets_.push_back(static_cast<int>(candidate_line_.size()));
    }
  }

  // Writes `in` cut by (edge, line) into `out`; false when the pose set becomes empty or a binary
  // vertical constraint with an assigned vertical correspondence fails.
  bool Extend(int edge, int line, const FeasibleRegion& in, FeasibleRegion* out) const {
    const MatchEdge& e = edges_[edge];
    const ObservedLine& l = lines_[line];
    if (!e.vertical) return AddNonVertical(l, e, prior_.height, options_.gate_sigmas, in, out);
    // The paper's binary constraint (inscribed-angle arc meets the prior disk, left-to-right
    // order) first: cheap; then the joint cut of the binned region, which subsumes it.
    for (const auto& [other_edge, other_line] : assigned_) {
      if (edges_[other_edge].vertical &&
          !BinaryVertical(lines_[other_line], l, AngleRange(other_edge, edge),
                          options_.gate_sigmas)) {
        return false;
      }
    }
    return AddVertical(l, e, options_.gate_sigmas, in, out);
  }

  double Bound() const { return std::max(pass_bound_, visitor_bound_); }

  // One node: `depth` decisions taken (each an assignment or a skip of one level). The next
  // level is the unprocessed one with the fewest alive candidates (most constrained first);
  // levels with none are left out (they cannot be matched any more).
  void Search(size_t depth, const FeasibleRegion& region) {
    if (stats_->nodes >= options_.max_nodes || stats_->leaves >= options_.max_hypotheses) {
      stats_->budget_exhausted = true;
      return;
    }
    ++stats_->nodes;
    const std::vector<char>& alive = alive_[depth];
    int next_level = -1, fewest = 0, open_levels = 0;
    const double reachable = Reachable(alive, &next_level, &fewest, &open_levels);
    if (static_cast<int>(assigned_.size()) + open_levels < options_.min_matches ||
        assigned_caps_ + reachable < Bound() || InBasin(region)) {
      return;
    }
    if (next_level < 0) {
      VisitLeaf(alive, region);
      return;
    }
    const Level& level = levels_[next_level];
    processed_[next_level] = true;
    for (int c = offsets_[next_level]; c < offsets_[next_level + 1]; ++c) {
      const int line = candidate_line_[c];
      if (!alive[c] || used_[line]) continue;
      // Regions live in one buffer per depth, reused: copying keeps their capacity.
      FeasibleRegion& next = regions_[depth + 1];
      if (!Extend(level.edge, line, region, &next)) continue;
      next.Refine(options_.max_bins, DegToRad(options_.heading_bin_deg));
      used_[line] = true;
      assigned_.emplace_back(level.edge, line);
      assigned_caps_ += caps_[line];
      level_assigned_[next_level] = line;
      ForwardCheck(depth, next, level.edge, line);
      Search(depth + 1, next);
      level_assigned_[next_level] = -1;
      assigned_caps_ -= caps_[line];
      assigned_.pop_back();
      used_[line] = false;
    }
    level_skipped_[next_level] = true;
    alive_[depth + 1] = alive;
    Search(depth + 1, region);
    level_skipped_[next_level] = false;
    processed_[next_level] = false;
  }

  // Forward checking: the candidates alive at `depth` that stay consistent with `region` after
  // (edge, line) was assigned there, written to alive_[depth + 1]. Candidates of used lines die.
  void ForwardCheck(size_t depth, const FeasibleRegion& region, int edge, int line) {
    const std::vector<char>& in = alive_[depth];
    std::vector<char>& out = alive_[depth + 1];
    const bool vertical = edges_[edge].vertical;
    for (size_t c = 0; c < candidate_line_.size(); ++c) {
      out[c] = 0;
      const int other_line = candidate_line_[c];
      if (!in[c] || used_[other_line]) continue;
      const int other_edge = levels_[candidate_level_[c]].edge;
      const MatchEdge& e = edges_[other_edge];
      const ObservedLine& l = lines_[other_line];
      if (e.vertical) {
        if (vertical && other_edge != edge &&
            !BinaryVertical(lines_[line], l, AngleRange(edge, other_edge), options_.gate_sigmas)) {
          continue;
        }
        out[c] = MeetsVertical(l, e, options_.gate_sigmas, region) ? 1 : 0;
      } else {
        out[c] = MeetsNonVertical(l, e, prior_.height, options_.gate_sigmas, region) ? 1 : 0;
      }
    }
  }

  // True when the region lies in the basin of a verified pose: its leaves are the same answer.
  bool InBasin(const FeasibleRegion& region) const {
    if (basins_ == nullptr) return false;
    return std::any_of(basins_->begin(), basins_->end(), [&](const VerifiedBasin& b) {
      return region.Within(b.pose, b.radius_m, b.heading_rad);
    });
  }

  void VisitLeaf(const std::vector<char>& alive, const FeasibleRegion& region) {
    if (!IsMaximal(alive, region)) return;
    // A leaf consistent with a verified pose would be verified into it again.
    if (basins_ != nullptr &&
        std::any_of(basins_->begin(), basins_->end(),
                    [&](const VerifiedBasin& b) { return region.Contains(b.pose); })) {
      return;
    }
    Hypothesis leaf{assigned_, region, assigned_caps_};
    // Fragments: unused lines an assigned edge could also take within the region.
    for (size_t c = 0; c < candidate_line_.size(); ++c) {
      const int line = candidate_line_[c];
      if (!alive[c] || used_[line] || line_mark_[line] ||
          level_assigned_[candidate_level_[c]] < 0) {
        continue;
      }
      line_mark_[line] = true;
      leaf.bound += caps_[line];
    }
    std::fill(line_mark_.begin(), line_mark_.end(), false);
    if (leaf.bound < Bound()) return;
    std::vector<std::pair<int, int>> key = leaf.pairs;
    std::sort(key.begin(), key.end());
    if (!visited_.insert(std::move(key)).second) return;
    ++stats_->leaves;
    visitor_bound_ = std::max(visitor_bound_, visit_(leaf));
  }

  // Inscribed-angle range of two vertical edges over the prior disk, computed once per pair.
  const HeadingInterval& AngleRange(int edge1, int edge2) const {
    const size_t key = static_cast<size_t>(edge1) * edges_.size() + edge2;
    if (angle_ranges_.empty()) angle_ranges_.resize(edges_.size() * edges_.size());
    if (!angle_ranges_[key]) {
      angle_ranges_[key] =
          InscribedAngleRange(edges_[edge1].foot, edges_[edge2].foot, prior_.centre, prior_.radius);
    }
    return *angle_ranges_[key];
  }

  // Upper bound on what the unprocessed levels can still add: the caps of the unused lines with
  // a candidate alive at an unprocessed level or at an assigned one (a second fragment).
  // *open_levels gets the unprocessed levels with an alive candidate, no more than the distinct
  // lines among them (each line matches one edge); *next_level the one of them with the fewest
  // (*fewest) alive candidates, -1 when there is none.
  double Reachable(const std::vector<char>& alive, int* next_level, int* fewest,
                   int* open_levels) const {
    double caps = 0.0;
    int lines = 0;
    *open_levels = 0;
    *next_level = -1;
    for (size_t d = 0; d < levels_.size(); ++d) {
      const bool open = !processed_[d];
      if (!open && level_assigned_[d] < 0) continue;
      int count = 0;
      for (int c = offsets_[d]; c < offsets_[d + 1]; ++c) {
        const int line = candidate_line_[c];
        if (!alive[c] || used_[line]) continue;
        ++count;
        if (line_mark_[line]) continue;
        line_mark_[line] = true;
        caps += caps_[line];
        ++lines;
      }
      if (!open || count == 0) continue;
      ++*open_levels;
      if (*next_level < 0 || count < *fewest) {
        *next_level = static_cast<int>(d);
        *fewest = count;
      }
    }
    std::fill(line_mark_.begin(), line_mark_.end(), false);
    *open_levels = std::min(*open_levels, lines);
    return caps;
  }

  // True when the extension keeps most of the region (at least half of its heading bins and a
  // bin of each run of contiguous bins): the leaf then adds nothing to it. An extension consistent
  // with only a part of the region (another pose cluster) does not make the leaf redundant.
  static bool KeepsEveryCluster(const FeasibleRegion& region, const FeasibleRegion& extended) {
    if (2 * extended.bins.size() < region.bins.size()) return false;
    size_t first = 0;
    for (size_t i = 1; i <= region.bins.size(); ++i) {
      const bool run_ends =
          i == region.bins.size() ||
          region.bins[i].lo - region.bins[i - 1].hi > 0.5 * (region.bins[i].hi - region.bins[i].lo);
      if (!run_ends) continue;
      const double lo = region.bins[first].lo, hi = region.bins[i - 1].hi;
      const bool kept = std::any_of(extended.bins.begin(), extended.bins.end(),
                                    [&](const HeadingBin& b) { return b.hi > lo && b.lo < hi; });
      if (!kept) return false;
      first = i;
    }
    return true;
  }

  // A leaf is kept only when no skipped edge could have been matched as well in every pose
  // cluster: every subset of a consistent assignment is consistent, and verifying those again
  // would be wasted work.
  bool IsMaximal(const std::vector<char>& alive, const FeasibleRegion& region) const {
    for (size_t d = 0; d < levels_.size(); ++d) {
      if (!level_skipped_[d]) continue;
      for (int c = offsets_[d]; c < offsets_[d + 1]; ++c) {
        const int line = candidate_line_[c];
        if (!alive[c] || used_[line]) continue;
        if (Extend(levels_[d].edge, line, region, &maximal_scratch_) &&
            KeepsEveryCluster(region, maximal_scratch_)) {
          return false;
        }
      }
    }
    return true;
  }

  const std::vector<MatchEdge>& edges_;
  const std::vector<ObservedLine>& lines_;
  const PriorRegion& prior_;
  const InterpretationTreeOptions& options_;
  const LeafVisitor& visit_;
  InterpretationTreeStats* stats_;
  const std::vector<VerifiedBasin>* basins_;
  Gate gate_;
  std::vector<double> caps_;
  std::vector<Level> levels_;
  // All candidates flattened by level: their level and line.
  std::vector<int> offsets_, candidate_level_, candidate_line_;
  // alive_[d][c]: candidate c is still consistent with the region at depth d (forward checking).
  std::vector<std::vector<char>> alive_;
  std::vector<bool> used_;
  std::vector<int> level_assigned_;      // line assigned at each level on the current branch, or -1
  std::vector<bool> level_skipped_;      // levels skipped on the current branch
  std::vector<bool> processed_;          // levels assigned or skipped on the current branch
  mutable std::vector<bool> line_mark_;  // scratch: lines counted once
  std::vector<FeasibleRegion> regions_;  // per depth
  mutable FeasibleRegion maximal_scratch_;
  std::vector<std::pair<int, int>> assigned_;
  double assigned_caps_ = 0.0;
  double pass_bound_ = 0.0;
  double visitor_bound_ = 0.0;
  std::set<std::vector<std::pair<int, int>>> visited_;
  mutable std::vector<std::optional<HeadingInterval>> angle_ranges_;
};

}  // namespace

bool InterpretationTreeOptions::Check(std::string* why) const {
  if (!(gate_sigmas > 0.0) || min_matches < 2 || max_nodes < 1 || max_hypotheses < 1 ||
      !(heading_bin_deg > 0.0) || !(extent_slack_px >= 0.0) || max_bins < 1 ||
      !(deepening_lines > 0.0)) {
    *why =
        "interpretation tree: gate_sigmas > 0, min_matches >= 2, budgets >= 1, "
        "deepening_lines > 0";
    return false;
  }
  return true;
}

void SearchInterpretationTree(const std::vector<MatchEdge>& edges,
                              const std::vector<ObservedLine>& lines, const PriorRegion& prior,
                              const InterpretationTreeOptions& options,
                              const std::vector<double>& line_caps, const LeafVisitor& visit,
                              InterpretationTreeStats* stats,
                              const std::vector<VerifiedBasin>* basins) {
  *stats = InterpretationTreeStats();
  TreeSearch(edges, lines, prior, options, line_caps, visit, stats, basins).Run();
}

std::vector<Hypothesis> GenerateHypotheses(const std::vector<MatchEdge>& edges,
                                           const std::vector<ObservedLine>& lines,
                                           const PriorRegion& prior,
                                           const InterpretationTreeOptions& options,
                                           InterpretationTreeStats* stats) {
  std::vector<Hypothesis> leaves;
  SearchInterpretationTree(
      edges, lines, prior, options, {},
      [&](const Hypothesis& h) {
        leaves.push_back(h);
        return 0.0;
      },
      stats);
  return leaves;
}

}  // namespace linetrack
